#pragma once
// Opening an MP4 (or MKV, AVI) file for the pictures of `gvkit render` and `gvkit compare`.

#include <filesystem>
#include <string>

#include "gvkit/core/opencv_media.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::tools {

// Opens `writer` on `path` for pictures of `size` at `fps` through FFmpeg: H.264 ('avc1') where
// this OpenCV/FFmpeg has it, else MPEG-4 ('mp4v'). Returns the four-character code used, or an
// I/O error naming the path when neither opens (unsupported when OpenCV's video codecs are
// missing, opencv_media.hpp).
Result<std::string> open_video(opencv_media::VideoWriter& writer, const std::filesystem::path& path,
                               double fps, cv::Size size);

}  // namespace gvkit::tools
