#pragma once
// FrameRecorder: crash-safe, append-only recording of raw camera frames into a folder
// (format: docs/frame_recording.md):
//   frame_NNNNNN.png   one lossless 8- or 16-bit grey PNG per frame, written atomically
//   frames.json        the index (format "gvkit-frames", version 1): per frame its file,
//                      sequence and timestamp; the source's drop/error counts; whether the
//                      recording was closed and why it stopped. Rewritten atomically after
//                      every frame (temp file + fsync + rename).
// A crash (even SIGKILL) at any moment leaves every frame the index lists readable; at most the
// frame being written is lost. A full disk stops the recording cleanly: what is written stays
// listed and readable, and the Status says so. `file:<folder>` replays it (file_frame_source.hpp).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "gvkit/capture/frame_source.hpp"

namespace gvkit {

struct FrameRecorderOptions {
  int png_compression = 1;              // 0..9 (zlib level; 1 = fast, still lossless)
  int64_t min_free_bytes = 64ll << 20;  // stop cleanly when less space than this is left
  std::string source_description;       // stored in the index ("v4l2:/dev/video0 ...")
  Status check() const;
};

class FrameRecorder {
 public:
  // Creates the folder (or uses an empty one). Fails when it already holds a recording
  // (frames.json): recordings are never overwritten.
  static Result<std::unique_ptr<FrameRecorder>> create(const std::filesystem::path& dir,
                                                       const FrameRecorderOptions& options);
  ~FrameRecorder();  // closes (marks the index complete) if close() was not called
  FrameRecorder(const FrameRecorder&) = delete;
  FrameRecorder& operator=(const FrameRecorder&) = delete;

  // Appends one frame (CV_8U/CV_16U, one channel, same size and type as the first). On a write
  // failure (disk full, I/O error) the recording stops: this and every later append return the
  // Status, which names the folder and how many frames were kept.
  Status append(const CameraFrame& frame);
  // The source's counters, stored in the index with the next write.
  void set_source_counters(const FrameSourceCounters& counters);
  // Marks the recording complete in the index. Idempotent.
  Status close();

  int64_t frames_written() const { return frames_written_; }
  const std::filesystem::path& dir() const { return dir_; }

 private:
  FrameRecorder(std::filesystem::path dir, FrameRecorderOptions options);
  Status write_index();
  Status stop(const Status& why);

  std::filesystem::path dir_;
  FrameRecorderOptions options_;
  nlohmann::json index_;
  int64_t frames_written_ = 0;
  cv::Size size_;
  int type_ = -1;
  bool closed_ = false;
  Status failure_;
};

}  // namespace gvkit
