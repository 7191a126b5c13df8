// The one file that talks to libcamera (Debian 12 ships 0.0.3, whose API still changes between
// releases): every libcamera type and error code stays in here.
#include "gvkit/capture/libcamera_source.hpp"

#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>

#include <libcamera/libcamera.h>

namespace gvkit {
namespace {

namespace lc = libcamera;

// libcamera allows one CameraManager per process: share it while anyone holds it.
Result<std::shared_ptr<lc::CameraManager>> shared_manager() {
  static std::mutex mutex;
  static std::weak_ptr<lc::CameraManager> current;
  std::lock_guard<std::mutex> lock(mutex);
  if (auto manager = current.lock()) return manager;
  // libcamera logs INFO lines on stderr by default; keep errors only unless the user chose.
  ::setenv("LIBCAMERA_LOG_LEVELS", "*:ERROR", /*overwrite=*/0);
  auto manager = std::make_shared<lc::CameraManager>();
  if (const int r = manager->start(); r < 0)
    return io_error(std::string("libcamera: the camera manager did not start: ") +
                    std::strerror(-r));
  // Stop before destruction (libcamera requires it).
  std::shared_ptr<lc::CameraManager> handle(manager.get(), [manager](lc::CameraManager*) mutable {
    manager->stop();
    manager.reset();
  });
  current = handle;
  return handle;
}

struct LumaFormat {
  lc::PixelFormat format;
  int cv_type;          // CV_8U or CV_16U
  int bytes_per_pixel;  // of the first plane
  int luma_step;        // bytes between luma samples (2 for YUYV)
};

// The formats gvkit reads, preferred first: mono sensors, then the luma of YUV streams.
const std::vector<LumaFormat>& luma_formats() {
  static const std::vector<LumaFormat> formats = {
      {lc::formats::R8, CV_8U, 1, 1},   {lc::formats::R10, CV_16U, 2, 2},
      {lc::formats::R12, CV_16U, 2, 2}, {lc::formats::YUYV, CV_8U, 2, 2},
      {lc::formats::NV12, CV_8U, 1, 1}, {lc::formats::YUV420, CV_8U, 1, 1},
  };
  return formats;
}

std::string no_cameras_message() {
  return "libcamera sees no cameras (libcamera " + lc::CameraManager::version() +
         "; check that a camera is connected and its pipeline handler is supported)";
}

std::vector<std::string> stream_format_lines(lc::Camera& camera) {
  std::vector<std::string> lines;
  std::unique_ptr<lc::CameraConfiguration> config =
      camera.generateConfiguration({lc::StreamRole::Raw});
  if (!config) config = camera.generateConfiguration({lc::StreamRole::Viewfinder});
  if (!config || config->size() == 0) return lines;
  const lc::StreamFormats& formats = config->at(0).formats();
  for (const lc::PixelFormat& pf : formats.pixelformats()) {
    std::string line = pf.toString();
    const std::vector<lc::Size> sizes = formats.sizes(pf);
    if (sizes.empty()) line += " " + formats.range(pf).toString();
    for (const lc::Size& s : sizes) line += " " + s.toString();
    lines.push_back(line);
  }
  return lines;
}

class LibcameraSource final : public FrameSource {
 public:
  LibcameraSource(std::shared_ptr<lc::CameraManager> manager, std::shared_ptr<lc::Camera> camera,
                  const FrameSourceOptions& options)
      : manager_(std::move(manager)), camera_(std::move(camera)), options_(options) {}

  ~LibcameraSource() override {
    if (started_) camera_->stop();
    camera_->requestCompleted.disconnect(this);
    camera_->disconnected.disconnect(this);
    requests_.clear();
    for (auto& [address, length] : mappings_) ::munmap(address, length);
    allocator_.reset();
    if (acquired_) camera_->release();
  }

  Status open() {
    const std::string name = "libcamera:" + camera_->id();
    if (camera_->acquire() < 0) return io_error(name + ": camera busy (another program holds it)");
    acquired_ = true;
    config_ = camera_->generateConfiguration({lc::StreamRole::Raw});
    if (!config_) config_ = camera_->generateConfiguration({lc::StreamRole::Viewfinder});
    if (!config_ || config_->size() == 0)
      return unsupported(name + ": the camera offers no stream configuration");
    lc::StreamConfiguration& stream_config = config_->at(0);
    const std::vector<lc::PixelFormat> offered = stream_config.formats().pixelformats();
    const LumaFormat* chosen = nullptr;
    for (const LumaFormat& f : luma_formats())
      if (std::find(offered.begin(), offered.end(), f.format) != offered.end()) {
        chosen = &f;
        break;
      }
    if (!chosen) {
      std::string list;
      for (const auto& pf : offered) list += (list.empty() ? "" : ", ") + pf.toString();
      return unsupported(name + ": no stream format gvkit reads; the camera offers " +
                         (list.empty() ? std::string("none") : list) +
                         "; gvkit reads R8, R10, R12, YUYV, NV12, YUV420");
    }
    format_ = *chosen;
    stream_config.pixelFormat = chosen->format;
    if (options_.width > 0)
      stream_config.size =
          lc::Size(static_cast<unsigned>(options_.width), static_cast<unsigned>(options_.height));
    stream_config.bufferCount = static_cast<unsigned>(options_.buffer_count);
    if (config_->validate() == lc::CameraConfiguration::Invalid)
      return unsupported(name + ": libcamera rejected the configuration " +
                         stream_config.toString());
    if (stream_config.pixelFormat != chosen->format)
      return unsupported(name + ": libcamera replaced " + chosen->format.toString() + " by " +
                         stream_config.pixelFormat.toString());
    if (options_.width > 0 && (static_cast<int>(stream_config.size.width) != options_.width ||
                               static_cast<int>(stream_config.size.height) != options_.height))
      refused_.push_back("size: asked " + std::to_string(options_.width) + "x" +
                         std::to_string(options_.height) + ", the camera gave " +
                         stream_config.size.toString());
    if (const int r = camera_->configure(config_.get()); r < 0)
      return io_error(name + ": configure failed: " + std::strerror(-r));
    width_ = static_cast<int>(stream_config.size.width);
    height_ = static_cast<int>(stream_config.size.height);
    stride_ = stream_config.stride;
    stream_ = stream_config.stream();

    allocator_ = std::make_unique<lc::FrameBufferAllocator>(camera_);
    if (allocator_->allocate(stream_) < 0)
      return io_error(name + ": cannot allocate frame buffers");
    for (const auto& buffer : allocator_->buffers(stream_)) {
      const lc::FrameBuffer::Plane& plane = buffer->planes().front();
      // mmap needs a page-aligned offset.
      const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
      const size_t aligned = plane.offset / page * page;
      const size_t length = plane.offset - aligned + plane.length;
      void* address = ::mmap(nullptr, length, PROT_READ, MAP_SHARED, plane.fd.get(),
                             static_cast<off_t>(aligned));
      if (address == MAP_FAILED)
        return io_error(name + ": cannot map a frame buffer: " + std::strerror(errno));
      mappings_.emplace_back(address, length);
      plane_data_[buffer.get()] = static_cast<const uint8_t*>(address) + (plane.offset - aligned);
      std::unique_ptr<lc::Request> request = camera_->createRequest();
      if (!request || request->addBuffer(stream_, buffer.get()) < 0)
        return io_error(name + ": cannot create a capture request");
      requests_.push_back(std::move(request));
    }
    camera_->requestCompleted.connect(this, &LibcameraSource::on_request_completed);
    camera_->disconnected.connect(this, &LibcameraSource::on_disconnected);

    lc::ControlList controls(camera_->controls());
    apply_controls(controls);
    if (const int r = camera_->start(&controls); r < 0)
      return io_error(name + ": start failed: " + std::strerror(-r));
    started_ = true;
    for (auto& request : requests_) {
      apply_controls(request->controls());
      if (camera_->queueRequest(request.get()) < 0)
        return io_error(name + ": cannot queue a capture request");
    }
    return Status::ok();
  }

  Result<std::optional<CameraFrame>> next() override {
    const std::string name = "libcamera:" + camera_->id();
    for (;;) {
      lc::Request* request = nullptr;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        const bool ready = condition_.wait_for(lock, std::chrono::milliseconds(options_.timeout_ms),
                                               [&] { return vanished_ || !completed_.empty(); });
        if (vanished_) return io_error(name + ": the camera vanished (disconnected)");
        if (!ready)
          return io_error(name + ": no frame within " + std::to_string(options_.timeout_ms) +
                          " ms");
        request = completed_.front();
        completed_.pop_front();
      }
      if (request->status() == lc::Request::RequestCancelled) {
        ++counters_.errored;
        requeue(request);
        continue;
      }
      lc::FrameBuffer* buffer = request->findBuffer(stream_);
      const lc::FrameMetadata& meta = buffer->metadata();
      if (have_sequence_ && meta.sequence > last_sequence_ + 1)
        counters_.dropped += meta.sequence - last_sequence_ - 1;
      if (!have_sequence_ || meta.sequence > last_sequence_) last_sequence_ = meta.sequence;
      have_sequence_ = true;
      if (meta.status != lc::FrameMetadata::FrameSuccess) {
        ++counters_.errored;
        requeue(request);
        continue;
      }
      CameraFrame frame;
      frame.image = copy_luma(plane_data_.at(buffer));
      frame.sequence = meta.sequence;
      Timestamp timestamp(static_cast<int64_t>(meta.timestamp));
      if (auto sensor = request->metadata().get(lc::controls::SensorTimestamp))
        timestamp = Timestamp(*sensor);
      if (have_timestamp_ && timestamp < last_timestamp_) {
        timestamp = last_timestamp_;
        ++counters_.clamped_timestamps;
      }
      last_timestamp_ = timestamp;
      have_timestamp_ = true;
      frame.timestamp = timestamp;
      if (auto exposure = request->metadata().get(lc::controls::ExposureTime))
        frame.exposure = std::chrono::microseconds(*exposure);
      requeue(request);
      ++counters_.frames;
      return std::optional<CameraFrame>(std::move(frame));
    }
  }

  FrameSourceCounters counters() const override { return counters_; }
  std::vector<std::string> refused_settings() const override { return refused_; }
  std::string describe() const override {
    return "libcamera:" + camera_->id() + " " + std::to_string(width_) + "x" +
           std::to_string(height_) + " " + format_.format.toString() + " stride " +
           std::to_string(stride_);
  }

 private:
  void apply_controls(lc::ControlList& controls) {
    const lc::ControlInfoMap& info = camera_->controls();
    if (options_.exposure_us > 0) {
      if (info.count(&lc::controls::ExposureTime)) {
        if (info.count(&lc::controls::AeEnable)) controls.set(lc::controls::AeEnable, false);
        controls.set(lc::controls::ExposureTime, static_cast<int32_t>(options_.exposure_us));
      } else if (!exposure_refused_) {
        exposure_refused_ = true;
        refused_.push_back("exposure: the camera has no ExposureTime control");
      }
    }
    if (options_.fps > 0) {
      if (info.count(&lc::controls::FrameDurationLimits)) {
        const int64_t duration_us = static_cast<int64_t>(1e6 / options_.fps);
        controls.set(lc::controls::FrameDurationLimits, {duration_us, duration_us});
      } else if (!fps_refused_) {
        fps_refused_ = true;
        refused_.push_back("fps: the camera has no FrameDurationLimits control");
      }
    }
  }

  void requeue(lc::Request* request) {
    request->reuse(lc::Request::ReuseBuffers);
    apply_controls(request->controls());
    camera_->queueRequest(request);
  }

  cv::Mat copy_luma(const uint8_t* data) const {
    cv::Mat out(height_, width_, format_.cv_type);
    for (int y = 0; y < height_; ++y) {
      const uint8_t* row = data + static_cast<size_t>(stride_) * y;
      if (format_.luma_step == format_.bytes_per_pixel || format_.cv_type == CV_16U) {
        std::memcpy(out.ptr(y), row, static_cast<size_t>(width_) * format_.bytes_per_pixel);
      } else {
        uint8_t* dst = out.ptr<uint8_t>(y);
        for (int x = 0; x < width_; ++x) dst[x] = row[x * format_.luma_step];
      }
    }
    return out;
  }

  void on_request_completed(lc::Request* request) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      completed_.push_back(request);
    }
    condition_.notify_one();
  }
  void on_disconnected() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      vanished_ = true;
    }
    condition_.notify_one();
  }

  std::shared_ptr<lc::CameraManager> manager_;
  std::shared_ptr<lc::Camera> camera_;
  FrameSourceOptions options_;
  bool acquired_ = false, started_ = false;
  std::unique_ptr<lc::CameraConfiguration> config_;
  std::unique_ptr<lc::FrameBufferAllocator> allocator_;
  std::vector<std::unique_ptr<lc::Request>> requests_;
  std::vector<std::pair<void*, size_t>> mappings_;
  std::map<const lc::FrameBuffer*, const uint8_t*> plane_data_;
  lc::Stream* stream_ = nullptr;
  LumaFormat format_{};
  int width_ = 0, height_ = 0;
  unsigned stride_ = 0;
  bool exposure_refused_ = false, fps_refused_ = false;
  std::vector<std::string> refused_;
  std::mutex mutex_;
  std::condition_variable condition_;
  std::deque<lc::Request*> completed_;
  bool vanished_ = false;
  bool have_sequence_ = false, have_timestamp_ = false;
  unsigned last_sequence_ = 0;
  Timestamp last_timestamp_{0};
  FrameSourceCounters counters_;
};

}  // namespace

Result<std::vector<LibcameraCameraInfo>> list_libcamera_cameras() {
  GVKIT_ASSIGN_OR_RETURN(std::shared_ptr<lc::CameraManager> manager, shared_manager());
  std::vector<LibcameraCameraInfo> cameras;
  for (const std::shared_ptr<lc::Camera>& camera : manager->cameras()) {
    LibcameraCameraInfo info;
    info.id = camera->id();
    if (auto model = camera->properties().get(lc::properties::Model)) info.model = *model;
    info.formats = stream_format_lines(*camera);
    cameras.push_back(std::move(info));
  }
  return cameras;
}

Result<std::unique_ptr<FrameSource>> open_libcamera_source(const std::string& id,
                                                           const FrameSourceOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  GVKIT_ASSIGN_OR_RETURN(std::shared_ptr<lc::CameraManager> manager, shared_manager());
  const std::vector<std::shared_ptr<lc::Camera>> cameras = manager->cameras();
  if (cameras.empty()) return not_found("libcamera:" + id + ": " + no_cameras_message());
  std::shared_ptr<lc::Camera> camera;
  if (id.empty()) {
    camera = cameras.front();
  } else if (id.find_first_not_of("0123456789") == std::string::npos && id.size() < 4) {
    const size_t n = std::stoul(id);
    if (n < cameras.size()) camera = cameras[n];
  } else {
    camera = manager->get(id);
  }
  if (!camera) {
    std::string ids;
    for (const auto& c : cameras) ids += (ids.empty() ? "" : ", ") + c->id();
    return not_found("libcamera:" + id + ": no such camera; libcamera sees " + ids);
  }
  auto source = std::make_unique<LibcameraSource>(manager, camera, options);
  GVKIT_RETURN_IF_ERROR(source->open());
  return std::unique_ptr<FrameSource>(std::move(source));
}

}  // namespace gvkit
