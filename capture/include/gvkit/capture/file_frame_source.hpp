#pragma once
// Replay of recorded frames as a FrameSource ("file:<path>"):
//  - a folder of images: frame_NNNNNN.<ext> files when there are any, else every image file
//    (.png .pgm .tif .tiff .bmp .jpg .jpeg) in name order; read as grey, 8 or 16 bit as stored.
//    A folder written by FrameRecorder (frames.json) replays with its recorded sequence numbers,
//    timestamps and drop count.
//  - a session folder (session.json, session_info.hpp): its frames image by image, each tagged
//    with its pattern (CameraFrame::pattern = k for image k), sequence = frame index * N + k, and
//    the frame's recorded timestamp (unpaced); the session's dropped frames are counted as
//    dropped.
//  - a video file (anything OpenCV videoio / FFmpeg opens), converted to grey.
// Without recorded timestamps, frame i gets i / fps (options.fps, else the video's rate, else
// 30 fps). options.paced replays in real time, options.loop starts again at the end.

#include <memory>
#include <string>

#include "gvkit/capture/frame_source.hpp"

namespace gvkit {

// Fails naming path when it is missing, an empty folder, or a file no decoder opens. A frame that
// later fails to decode or changes size ends the stream with a Status naming that file.
Result<std::unique_ptr<FrameSource>> open_file_source(const std::string& path,
                                                      const FrameSourceOptions& options);

}  // namespace gvkit
