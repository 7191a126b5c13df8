#include "gvkit/capture/frame_recorder.hpp"

#include <opencv2/imgcodecs.hpp>  // the flags only: the codecs are in the plugin

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/opencv_media.hpp"

namespace gvkit {
namespace fs = std::filesystem;

Status FrameRecorderOptions::check() const {
  if (png_compression < 0 || png_compression > 9)
    return invalid_argument("recorder: png_compression " + std::to_string(png_compression) +
                            " is outside 0..9");
  if (min_free_bytes < 0) return invalid_argument("recorder: min_free_bytes is negative");
  return Status::ok();
}

FrameRecorder::FrameRecorder(fs::path dir, FrameRecorderOptions options)
    : dir_(std::move(dir)), options_(std::move(options)) {
  index_ = {{"format", "gvkit-frames"},
            {"version", 1},
            {"source", options_.source_description},
            {"width", 0},
            {"height", 0},
            {"bits", 0},
            {"dropped", 0},
            {"errored", 0},
            {"complete", false},
            {"stop_reason", ""},
            {"frames", nlohmann::json::array()}};
}

FrameRecorder::~FrameRecorder() { static_cast<void>(close()); }

Result<std::unique_ptr<FrameRecorder>> FrameRecorder::create(const fs::path& dir,
                                                             const FrameRecorderOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  GVKIT_RETURN_IF_ERROR(ensure_directory(dir));
  std::error_code ec;
  if (fs::exists(dir / "frames.json", ec))
    return failed_precondition(dir.string() +
                               ": already holds a recording (frames.json); choose a new folder");
  std::unique_ptr<FrameRecorder> recorder(new FrameRecorder(dir, options));
  GVKIT_RETURN_IF_ERROR(recorder->write_index());
  return recorder;
}

Status FrameRecorder::write_index() { return write_json(dir_ / "frames.json", index_, 1); }

Status FrameRecorder::stop(const Status& why) {
  failure_ = Status(why.code(), dir_.string() + ": recording stopped after " +
                                    std::to_string(frames_written_) +
                                    " frames (all kept): " + why.message());
  index_["stop_reason"] = why.message();
  // Best effort: on a full disk this may fail too, and the previous index stays valid.
  static_cast<void>(write_index());
  return failure_;
}

void FrameRecorder::set_source_counters(const FrameSourceCounters& counters) {
  index_["dropped"] = counters.dropped;
  index_["errored"] = counters.errored;
}

Status FrameRecorder::append(const CameraFrame& frame) {
  if (!failure_.is_ok()) return failure_;
  GVKIT_CHECK(!closed_, "append() after close()");
  const cv::Mat& image = frame.image;
  if (image.empty() || image.channels() != 1 || (image.depth() != CV_8U && image.depth() != CV_16U))
    return invalid_argument(dir_.string() + ": frame " + std::to_string(frames_written_) +
                            ": expected a one-channel 8- or 16-bit image");
  if (type_ < 0) {
    size_ = image.size();
    type_ = image.type();
    index_["width"] = size_.width;
    index_["height"] = size_.height;
    index_["bits"] = image.depth() == CV_16U ? 16 : 8;
  } else if (image.size() != size_ || image.type() != type_) {
    return invalid_argument(dir_.string() + ": frame " + std::to_string(frames_written_) + ": " +
                            std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                            " differs from the recording's first frame");
  }
  if (options_.min_free_bytes > 0) {
    std::error_code ec;
    const fs::space_info space = fs::space(dir_, ec);
    if (!ec && static_cast<int64_t>(space.available) < options_.min_free_bytes)
      return stop(io_error("the disk is nearly full (" + std::to_string(space.available >> 20) +
                           " MiB free, at least " + std::to_string(options_.min_free_bytes >> 20) +
                           " MiB wanted)"));
  }
  std::vector<uint8_t> png;
  const Result<bool> encoded = opencv_media::imencode(
      ".png", image, &png, {cv::IMWRITE_PNG_COMPRESSION, options_.png_compression});
  if (!encoded.is_ok() || !encoded.value())
    return stop(io_error("frame " + std::to_string(frames_written_) + ": PNG encoding failed" +
                         (encoded.is_ok() ? "" : " (" + encoded.status().message() + ")")));
  const std::string name = frame_file_name(frames_written_, ".png");
  Status written = write_file_atomically(
      dir_ / name, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
  if (!written.is_ok()) return stop(written);
  index_["frames"].push_back({{"file", name},
                              {"index", frames_written_},
                              {"sequence", frame.sequence},
                              {"timestamp_ns", frame.timestamp.count()}});
  Status indexed = write_index();
  if (!indexed.is_ok()) {
    index_["frames"].erase(index_["frames"].size() - 1);  // not listed: as if never written
    std::error_code ec;
    fs::remove(dir_ / name, ec);
    return stop(indexed);
  }
  ++frames_written_;
  return Status::ok();
}

Status FrameRecorder::close() {
  if (closed_) return Status::ok();
  closed_ = true;
  index_["complete"] = true;
  Status s = write_index();
  return failure_.is_ok() ? s : Status::ok();
}

}  // namespace gvkit
