#pragma once
// FrameSource: a stream of grey camera frames from a live device, a replayed file or a generator.
// One interface, one backend per file, chosen by URI:
//   v4l2:/dev/videoN      a V4L2 device, mmap streaming (GREY, Y16, YUYV luma, MJPEG)
//   libcamera:<id>        a libcamera camera by id (or by index "libcamera:0")
//   file:<path>           a folder of images (frame_NNNNNN.png or any sorted image files), a
//                         session folder (frames tagged with their patterns), or a video file
//                         (OpenCV videoio / FFmpeg)
//   synthetic:            the generator in FrameSourceOptions::synthetic_generator (the
//                         projector-camera renderer: SyntheticStream::generator(),
//                         synthetic_stream.hpp)

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/status.hpp"
#include "gvkit/core/timestamp.hpp"

namespace gvkit {

struct CameraFrame {
  cv::Mat image;           // CV_8U or CV_16U, one channel (grey / luma); owns its pixels
  int64_t sequence = 0;    // the source's frame counter; gaps mean frames were dropped
  Timestamp timestamp{0};  // monotonic ns (start of exposure where the source knows it)
  Timestamp exposure{0};   // exposure duration where known, else 0
  // Position of the projected pattern this frame saw, where the source knows it (synthetic:
  // frame index mod FrameSourceOptions::pattern_cycle; replay of a session folder); -1 when
  // unknown (cameras: pattern_sync.hpp finds it) or for a frame that is no fringe image (a cue).
  int pattern = -1;
};

// What a source has done so far. frames counts delivered frames; dropped counts frames the
// device produced that never reached us (sequence gaps); errored counts frames discarded because
// the device flagged them or they could not be decoded; clamped_timestamps counts timestamps that
// went backwards and were clamped to stay monotonic; retries counts EINTR/EAGAIN retries.
struct FrameSourceCounters {
  int64_t frames = 0;
  int64_t dropped = 0;
  int64_t errored = 0;
  int64_t clamped_timestamps = 0;
  int64_t retries = 0;
};

// A generator for synthetic: and callback sources: the image of frame `index` (CV_8U/CV_16U, one
// channel), an empty Mat at the end of the stream, or a Status on failure.
using FrameGenerator = std::function<Result<cv::Mat>(int64_t index)>;

struct FrameSourceOptions {
  int width = 0;  // requested size in px; 0 = the device's current size
  int height = 0;
  double fps = 0;                      // requested frame rate; 0 = device default / file's own rate
  double exposure_us = 0;              // manual exposure (microseconds); 0 = leave auto / as is
  std::string pixel_format = "auto";   // auto | GREY | Y16 | YUYV | MJPG (V4L2); auto picks the
                                       // first of those the device offers
  int buffer_count = 4;                // V4L2 mmap buffers / libcamera requests, 2..32
  int timeout_ms = 2000;               // longest wait for one frame before a timeout Status
  bool paced = false;                  // file/synthetic: deliver at fps in real time (else at once)
  bool loop = false;                   // file: start again at the end
  int64_t frame_count = 0;             // synthetic/callback: stop after this many (0 = until the
                                       // generator returns an empty image)
  FrameGenerator synthetic_generator;  // the image source behind "synthetic:"
  // synthetic/callback: frames per projected pattern cycle; > 0 tags frame i with pattern
  // (i mod pattern_cycle) - cue_frames, or -1 for the cue_frames cue frames that open each cycle
  // (0 = untagged).
  int pattern_cycle = 0;
  int cue_frames = 0;
  // synthetic/callback, paced: behave like a camera: a frame whose time slot passed while the
  // consumer was busy is never generated; it is counted as dropped (a sequence gap). Time spent
  // inside the generator pauses the clock (a slow simulation lowers the rate, it drops nothing).
  bool drop_late = false;

  // Names the first out-of-range field ("fps: -1 is negative").
  Status check() const;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // The next frame; waits up to options.timeout_ms. std::nullopt at the end of a finite stream
  // (files, generators). Failures (device gone, timeout, corrupt file) are a Status naming the
  // source; after a failure the source stays failed.
  virtual Result<std::optional<CameraFrame>> next() = 0;

  virtual FrameSourceCounters counters() const = 0;
  // One line: URI, size, pixel format, fps ("v4l2:/dev/video0 uvcvideo 'HD Cam' 640x480 GREY 30
  // fps").
  virtual std::string describe() const = 0;
  // Settings the source could not apply as asked (fps, exposure refused by the driver), one line
  // each. Empty when everything requested was applied.
  virtual std::vector<std::string> refused_settings() const { return {}; }

  // Opens the source named by uri (see the top of this file). Fails with a Status naming the URI:
  // unknown scheme, missing device or file, permission denied, busy device, unsupported format
  // (listing the supported ones), bad options.
  static Result<std::unique_ptr<FrameSource>> create(const std::string& uri,
                                                     const FrameSourceOptions& options);
};

}  // namespace gvkit
