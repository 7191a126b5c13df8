#include "gvkit/capture/file_frame_source.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <utility>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>  // the constants only: the codecs are in the plugin

#include "gvkit/capture/session_reader.hpp"
#include "gvkit/core/file_extension.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/opencv_media.hpp"
#include "pacer.hpp"

namespace gvkit {
namespace {
namespace fs = std::filesystem;

constexpr double kDefaultReplayFps = 30.0;

struct ListedFrame {
  fs::path path;
  int64_t sequence = 0;
  std::optional<Timestamp> timestamp;
};

bool is_image_file(const fs::path& path) {
  static const char* kExtensions[] = {".png", ".pgm", ".tif", ".tiff", ".bmp", ".jpg", ".jpeg"};
  const std::string ext = lower_extension(path);
  return std::any_of(std::begin(kExtensions), std::end(kExtensions),
                     [&](const char* e) { return ext == e; });
}

Timestamp timestamp_at(int64_t index, double fps) {
  return Timestamp(static_cast<int64_t>(static_cast<double>(index) * 1e9 / fps));
}

// The frames of a FrameRecorder folder (frames.json): only frames the index lists, so a frame
// whose write was cut short by a crash is never replayed.
Result<std::vector<ListedFrame>> list_recorded_frames(const fs::path& dir, int64_t* dropped) {
  GVKIT_ASSIGN_OR_RETURN(nlohmann::json index, read_json(dir / "frames.json"));
  std::vector<ListedFrame> frames;
  try {
    if (index.value("format", "") != "gvkit-frames")
      return corrupt_data((dir / "frames.json").string() + ": not a gvkit-frames index");
    *dropped = index.value("dropped", int64_t{0});
    for (const auto& f : index.at("frames")) {
      ListedFrame frame;
      frame.path = dir / f.at("file").get<std::string>();
      frame.sequence = f.at("sequence").get<int64_t>();
      frame.timestamp = Timestamp(f.at("timestamp_ns").get<int64_t>());
      frames.push_back(std::move(frame));
    }
  } catch (const nlohmann::json::exception& e) {
    return corrupt_data((dir / "frames.json").string() + ": " + e.what());
  }
  return frames;
}

Result<std::vector<ListedFrame>> list_image_folder(const fs::path& dir) {
  std::vector<ListedFrame> frames;
  GVKIT_ASSIGN_OR_RETURN(std::vector<FrameFile> numbered, list_frame_files(dir, ".png"));
  if (numbered.empty()) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir, ec))
      if (entry.is_regular_file() && is_image_file(entry.path())) files.push_back(entry.path());
    if (ec) return io_error(dir.string() + ": cannot list the folder: " + ec.message());
    std::sort(files.begin(), files.end());
    for (size_t i = 0; i < files.size(); ++i)
      frames.push_back({files[i], static_cast<int64_t>(i), std::nullopt});
  } else {
    for (const auto& f : numbered) frames.push_back({f.path, f.index, std::nullopt});
  }
  if (frames.empty()) return not_found(dir.string() + ": no image files in the folder");
  return frames;
}

class ImageFolderSource final : public FrameSource {
 public:
  ImageFolderSource(fs::path dir, std::vector<ListedFrame> frames, int64_t recorded_drops,
                    const FrameSourceOptions& options)
      : dir_(std::move(dir)),
        frames_(std::move(frames)),
        options_(options),
        fps_(options.fps > 0 ? options.fps : kDefaultReplayFps),
        pacer_(options.paced ? fps_ : 0) {
    counters_.dropped = recorded_drops;
  }

  Result<std::optional<CameraFrame>> next() override {
    if (!failure_.is_ok()) return failure_;
    if (position_ >= frames_.size()) {
      if (!options_.loop || frames_.empty()) return std::optional<CameraFrame>();
      position_ = 0;
      ++loops_;
    }
    const ListedFrame& listed = frames_[position_];
    Result<cv::Mat> image = read_image(listed.path, /*grey=*/true);
    if (!image.is_ok()) return failure_ = image.status();
    if (first_size_.empty()) {
      first_size_ = image->size();
      first_depth_ = image->depth();
    } else if (image->size() != first_size_ || image->depth() != first_depth_) {
      return failure_ = corrupt_data(
                 listed.path.string() + ": size " + std::to_string(image->cols) + "x" +
                 std::to_string(image->rows) +
                 " or depth differs from the "
                 "first frame's " +
                 std::to_string(first_size_.width) + "x" + std::to_string(first_size_.height));
    }
    const int64_t index = static_cast<int64_t>(delivered_);
    pacer_.wait_for(index);
    CameraFrame frame;
    frame.image = std::move(image).value();
    frame.sequence = listed.sequence + loops_ * (frames_.back().sequence + 1);
    frame.timestamp = listed.timestamp && loops_ == 0 ? *listed.timestamp
                      : options_.paced                ? monotonic_now()
                                                      : timestamp_at(index, fps_);
    ++position_;
    ++delivered_;
    ++counters_.frames;
    return std::optional<CameraFrame>(std::move(frame));
  }

  FrameSourceCounters counters() const override { return counters_; }
  std::string describe() const override {
    std::string text = "file:" + dir_.string() + " (" + std::to_string(frames_.size()) + " images";
    if (!first_size_.empty())
      text += ", " + std::to_string(first_size_.width) + "x" + std::to_string(first_size_.height) +
              (first_depth_ == CV_16U ? " 16-bit" : " 8-bit");
    return text + ")";
  }

 private:
  fs::path dir_;
  std::vector<ListedFrame> frames_;
  FrameSourceOptions options_;
  double fps_;
  detail::Pacer pacer_;
  size_t position_ = 0, delivered_ = 0;
  int64_t loops_ = 0;
  cv::Size first_size_;
  int first_depth_ = -1;
  Status failure_;
  FrameSourceCounters counters_;
};

class VideoFileSource final : public FrameSource {
 public:
  VideoFileSource(fs::path path, opencv_media::VideoCapture capture,
                  const FrameSourceOptions& options)
      : path_(std::move(path)), capture_(std::move(capture)), options_(options) {
    const double file_fps = capture_.get(cv::CAP_PROP_FPS);
    fps_ = options.fps > 0 ? options.fps : (file_fps > 0 ? file_fps : kDefaultReplayFps);
    pacer_ = detail::Pacer(options.paced ? fps_ : 0);
  }

  Result<std::optional<CameraFrame>> next() override {
    if (!failure_.is_ok()) return failure_;
    cv::Mat raw;
    Result<bool> read = capture_.read(&raw);
    if (!read.is_ok()) return failure_ = read.status().with_context(path_.string());
    if (!read.value()) {
      if (!options_.loop || delivered_ == 0) return std::optional<CameraFrame>();
      capture_.set(cv::CAP_PROP_POS_FRAMES, 0);
      read = capture_.read(&raw);
      if (!read.is_ok()) return failure_ = read.status().with_context(path_.string());
      if (!read.value())
        return failure_ = io_error(path_.string() + ": cannot seek back to the first frame");
    }
    cv::Mat grey;
    if (raw.channels() == 3)
      cv::cvtColor(raw, grey, cv::COLOR_BGR2GRAY);
    else if (raw.channels() == 4)
      cv::cvtColor(raw, grey, cv::COLOR_BGRA2GRAY);
    else
      grey = raw.clone();
    pacer_.wait_for(delivered_);
    CameraFrame frame;
    frame.image = grey;
    frame.sequence = delivered_;
    frame.timestamp = options_.paced ? monotonic_now() : timestamp_at(delivered_, fps_);
    ++delivered_;
    ++counters_.frames;
    if (size_.empty()) size_ = grey.size();
    return std::optional<CameraFrame>(std::move(frame));
  }

  FrameSourceCounters counters() const override { return counters_; }
  std::string describe() const override {
    return "file:" + path_.string() + " (video, " +
           std::to_string(static_cast<int>(capture_.get(cv::CAP_PROP_FRAME_WIDTH))) + "x" +
           std::to_string(static_cast<int>(capture_.get(cv::CAP_PROP_FRAME_HEIGHT))) + ", " +
           std::to_string(fps_) + " fps)";
  }

 private:
  fs::path path_;
  opencv_media::VideoCapture capture_;
  FrameSourceOptions options_;
  double fps_ = kDefaultReplayFps;
  detail::Pacer pacer_{0};
  int64_t delivered_ = 0;
  cv::Size size_;
  Status failure_;
  FrameSourceCounters counters_;
};

// A session folder (session.json) replayed image by image: frame f's image k comes out as
// sequence f.index * N + k tagged with pattern k, carrying f's recorded timestamp, so a sync on
// the tags rebuilds the recorded fringe sets (and a dropped frame of the recording stays a gap).
class SessionReplaySource final : public FrameSource {
 public:
  SessionReplaySource(capture::SessionReader reader, const FrameSourceOptions& options)
      : reader_(std::move(reader)),
        options_(options),
        n_(reader_.info().images_per_frame),
        pacer_(options.paced ? options.fps : 0) {
    counters_.dropped = reader_.info().dropped_frames * n_;
  }

  Result<std::optional<CameraFrame>> next() override {
    if (!failure_.is_ok()) return failure_;
    if (image_ == 0) {
      if (position_ >= reader_.frame_count()) {
        if (!options_.loop || reader_.frame_count() == 0) return std::optional<CameraFrame>();
        position_ = 0;
        ++loops_;
      }
      Result<FringeSet> set = reader_.read_frame(position_);
      if (!set.is_ok())
        return failure_ = set.status().with_context("file:" + reader_.dir().string());
      current_ = std::move(set).value();
    }
    pacer_.wait_for(delivered_);
    const int64_t span =
        reader_.info().frames.empty() ? 0 : (reader_.info().frames.back().index + 1) * n_;
    CameraFrame frame;
    frame.image = current_.images[static_cast<size_t>(image_)];
    frame.sequence = current_.index * n_ + image_ + loops_ * span;
    frame.pattern = image_;
    frame.timestamp = options_.paced ? monotonic_now() : current_.timestamp;
    ++delivered_;
    ++counters_.frames;
    if (++image_ == n_) {
      image_ = 0;
      ++position_;
    }
    return std::optional<CameraFrame>(std::move(frame));
  }

  FrameSourceCounters counters() const override { return counters_; }
  std::string describe() const override {
    const capture::SessionInfo& info = reader_.info();
    return "file:" + reader_.dir().string() + " (session, " + std::to_string(info.frames.size()) +
           " frames of " + std::to_string(n_) + " images, " + info.pattern + ", " +
           std::to_string(info.width) + "x" + std::to_string(info.height) + ")";
  }

 private:
  capture::SessionReader reader_;
  FrameSourceOptions options_;
  int n_;
  detail::Pacer pacer_;
  size_t position_ = 0;
  int image_ = 0;
  int64_t loops_ = 0, delivered_ = 0;
  FringeSet current_;
  Status failure_;
  FrameSourceCounters counters_;
};

}  // namespace

Result<std::unique_ptr<FrameSource>> open_file_source(const std::string& path_text,
                                                      const FrameSourceOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  const fs::path path(path_text);
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found(path_text + ": no such file or folder");
  if (fs::is_directory(path, ec)) {
    if (fs::exists(path / "session.json", ec)) {
      GVKIT_ASSIGN_OR_RETURN(capture::SessionReader reader, capture::SessionReader::open(path));
      if (reader.frame_count() == 0) return not_found(path_text + ": the session holds no frames");
      return std::unique_ptr<FrameSource>(
          std::make_unique<SessionReplaySource>(std::move(reader), options));
    }
    int64_t dropped = 0;
    Result<std::vector<ListedFrame>> frames = fs::exists(path / "frames.json", ec)
                                                  ? list_recorded_frames(path, &dropped)
                                                  : list_image_folder(path);
    if (!frames.is_ok()) return frames.status();
    if (frames->empty()) return not_found(path_text + ": the recording holds no frames");
    return std::unique_ptr<FrameSource>(
        std::make_unique<ImageFolderSource>(path, std::move(frames).value(), dropped, options));
  }
  if (is_image_file(path))
    return unsupported(path_text +
                       ": a single image; file: replays a folder of images or a video file");
  opencv_media::VideoCapture capture;
  GVKIT_RETURN_IF_ERROR(capture.open(path_text, cv::CAP_FFMPEG));
  return std::unique_ptr<FrameSource>(
      std::make_unique<VideoFileSource>(path, std::move(capture), options));
}

}  // namespace gvkit
