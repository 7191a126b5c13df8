#include "gvkit/capture/v4l2_source.hpp"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>  // the flags only: the codecs are in the plugin

#include "gvkit/core/opencv_media.hpp"

#include "v4l2_errors.hpp"

namespace gvkit {
namespace {

using detail::v4l2_errno_status;

// The pixel formats gvkit reads, in the order "auto" prefers them.
constexpr uint32_t kReadableFormats[] = {V4L2_PIX_FMT_GREY, V4L2_PIX_FMT_Y16, V4L2_PIX_FMT_YUYV,
                                         V4L2_PIX_FMT_MJPEG};
constexpr int kMaxConsecutiveIoErrors = 16;

uint32_t fourcc_from_name(const std::string& name) {
  if (name == "GREY") return V4L2_PIX_FMT_GREY;
  if (name == "Y16") return V4L2_PIX_FMT_Y16;
  if (name == "YUYV") return V4L2_PIX_FMT_YUYV;
  if (name == "MJPG") return V4L2_PIX_FMT_MJPEG;
  return 0;
}

// Bytes per pixel of the packed formats; 0 for compressed ones.
int bytes_per_pixel(uint32_t fourcc) {
  switch (fourcc) {
    case V4L2_PIX_FMT_GREY:
      return 1;
    case V4L2_PIX_FMT_Y16:
    case V4L2_PIX_FMT_YUYV:
      return 2;
    default:
      return 0;
  }
}

struct MappedBuffer {
  void* data = MAP_FAILED;
  size_t length = 0;
};

class V4l2Source final : public FrameSource {
 public:
  V4l2Source(std::string device, std::shared_ptr<V4l2Io> io, const FrameSourceOptions& options)
      : device_(std::move(device)), io_(std::move(io)), options_(options) {}

  ~V4l2Source() override {
    if (fd_ < 0) return;
    if (streaming_) {
      int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      io_->ioctl(fd_, VIDIOC_STREAMOFF, &type);
    }
    for (auto& b : buffers_)
      if (b.data != MAP_FAILED) io_->munmap(b.data, b.length);
    io_->close(fd_);
  }

  Status open() {
    fd_ = io_->open(device_, O_RDWR | O_NONBLOCK);
    if (fd_ < 0) return v4l2_errno_status(device_, "open", errno);
    GVKIT_RETURN_IF_ERROR(query_capabilities());
    GVKIT_RETURN_IF_ERROR(set_format());
    GVKIT_RETURN_IF_ERROR(set_frame_rate());
    GVKIT_RETURN_IF_ERROR(set_exposure());
    GVKIT_RETURN_IF_ERROR(start_streaming());
    return Status::ok();
  }

  Result<std::optional<CameraFrame>> next() override {
    if (!failure_.is_ok()) return failure_;
    Result<std::optional<CameraFrame>> frame = next_frame();
    if (!frame.is_ok()) failure_ = frame.status();
    return frame;
  }

  FrameSourceCounters counters() const override { return counters_; }
  std::vector<std::string> refused_settings() const override { return refused_; }

  std::string describe() const override {
    std::string text = "v4l2:" + device_ + " (" + driver_ + " '" + card_ + "') " +
                       std::to_string(width_) + "x" + std::to_string(height_) + " " +
                       fourcc_name(fourcc_);
    if (bytes_per_pixel(fourcc_) > 0) text += " stride " + std::to_string(stride_);
    if (fps_ > 0) text += ", " + std::to_string(fps_) + " fps";
    return text;
  }

 private:
  int xioctl(unsigned long request, void* arg) {
    int r;
    do {
      r = io_->ioctl(fd_, request, arg);
    } while (r < 0 && errno == EINTR && (++counters_.retries, true));
    return r;
  }

  Status query_capabilities() {
    v4l2_capability cap{};
    if (xioctl(VIDIOC_QUERYCAP, &cap) < 0)
      return v4l2_errno_status(device_, "VIDIOC_QUERYCAP", errno);
    driver_ = reinterpret_cast<const char*>(cap.driver);
    card_ = reinterpret_cast<const char*>(cap.card);
    const uint32_t caps =
        (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE))
      return unsupported(device_ + ": '" + card_ + "' is not a video capture device");
    if (!(caps & V4L2_CAP_STREAMING))
      return unsupported(device_ + ": '" + card_ + "' does not support streaming I/O");
    return Status::ok();
  }

  Status set_format() {
    std::vector<uint32_t> offered;
    for (uint32_t i = 0;; ++i) {
      v4l2_fmtdesc desc{};
      desc.index = i;
      desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      if (xioctl(VIDIOC_ENUM_FMT, &desc) < 0) {
        if (errno == EINVAL) break;
        return v4l2_errno_status(device_, "VIDIOC_ENUM_FMT", errno);
      }
      offered.push_back(desc.pixelformat);
    }
    auto offered_text = [&] {
      std::string s;
      for (uint32_t f : offered) s += (s.empty() ? "" : ", ") + fourcc_name(f);
      return s.empty() ? std::string("none") : s;
    };
    const std::string readable = "gvkit reads GREY, Y16, YUYV, MJPG";
    uint32_t wanted = 0;
    if (options_.pixel_format == "auto") {
      for (uint32_t f : kReadableFormats)
        if (std::find(offered.begin(), offered.end(), f) != offered.end()) {
          wanted = f;
          break;
        }
      if (wanted == 0)
        return unsupported(device_ + ": no pixel format gvkit reads; the device offers " +
                           offered_text() + "; " + readable);
    } else {
      wanted = fourcc_from_name(options_.pixel_format);
      if (std::find(offered.begin(), offered.end(), wanted) == offered.end())
        return unsupported(device_ + ": pixel format " + options_.pixel_format +
                           " is not offered; the device offers " + offered_text() + "; " +
                           readable);
    }

    v4l2_format fmt{};
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(VIDIOC_G_FMT, &fmt) < 0) return v4l2_errno_status(device_, "VIDIOC_G_FMT", errno);
    fmt.fmt.pix.pixelformat = wanted;
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
    if (options_.width > 0) {
      fmt.fmt.pix.width = static_cast<uint32_t>(options_.width);
      fmt.fmt.pix.height = static_cast<uint32_t>(options_.height);
    }
    fmt.fmt.pix.bytesperline = 0;  // let the driver choose the stride
    if (xioctl(VIDIOC_S_FMT, &fmt) < 0) {
      if (errno == EINVAL)
        return unsupported(device_ + ": the driver refused pixel format " + fourcc_name(wanted) +
                           "; the device offers " + offered_text() + "; " + readable);
      return v4l2_errno_status(device_, "VIDIOC_S_FMT", errno);
    }
    // The driver may have changed anything: read back what it will deliver.
    if (fmt.fmt.pix.pixelformat != wanted)
      return unsupported(device_ + ": the driver refused pixel format " + fourcc_name(wanted) +
                         " and offered " + fourcc_name(fmt.fmt.pix.pixelformat) +
                         " instead; the device offers " + offered_text() + "; " + readable);
    fourcc_ = wanted;
    if (fourcc_ == V4L2_PIX_FMT_MJPEG)  // its frames are decoded by OpenCV's codecs
      GVKIT_RETURN_IF_ERROR(opencv_media::load().with_context(device_ + ": MJPG frames"));
    width_ = static_cast<int>(fmt.fmt.pix.width);
    height_ = static_cast<int>(fmt.fmt.pix.height);
    if (width_ <= 0 || height_ <= 0)
      return unsupported(device_ + ": the driver reports an empty frame size");
    if (options_.width > 0 && (width_ != options_.width || height_ != options_.height))
      refused_.push_back("size: asked " + std::to_string(options_.width) + "x" +
                         std::to_string(options_.height) + ", the driver gave " +
                         std::to_string(width_) + "x" + std::to_string(height_));
    const size_t min_stride = static_cast<size_t>(width_) * bytes_per_pixel(fourcc_);
    stride_ = std::max<size_t>(fmt.fmt.pix.bytesperline, min_stride);
    image_bytes_ = fmt.fmt.pix.sizeimage;
    return Status::ok();
  }

  Status set_frame_rate() {
    v4l2_streamparm parm{};
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    const bool can_read = xioctl(VIDIOC_G_PARM, &parm) == 0;
    auto read_fps = [&] {
      const v4l2_fract& t = parm.parm.capture.timeperframe;
      return t.numerator > 0 ? static_cast<double>(t.denominator) / t.numerator : 0.0;
    };
    if (can_read) fps_ = read_fps();
    if (options_.fps <= 0) return Status::ok();
    if (!can_read || !(parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
      refused_.push_back("fps: the driver does not set frame rates (asked " +
                         std::to_string(options_.fps) + ")");
      return Status::ok();
    }
    parm.parm.capture.timeperframe.numerator = 1000;
    parm.parm.capture.timeperframe.denominator =
        static_cast<uint32_t>(std::lround(options_.fps * 1000));
    if (xioctl(VIDIOC_S_PARM, &parm) < 0) {
      if (errno == ENODEV) return v4l2_errno_status(device_, "VIDIOC_S_PARM", errno);
      refused_.push_back("fps: the driver refused " + std::to_string(options_.fps) + " (" +
                         std::strerror(errno) + ")");
      return Status::ok();
    }
    fps_ = read_fps();
    if (std::abs(fps_ - options_.fps) > 0.01 * options_.fps)
      refused_.push_back("fps: asked " + std::to_string(options_.fps) + ", the driver gave " +
                         std::to_string(fps_));
    return Status::ok();
  }

  Status set_exposure() {
    if (options_.exposure_us <= 0) return Status::ok();
    v4l2_control mode{V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_MANUAL};
    if (xioctl(VIDIOC_S_CTRL, &mode) < 0 && errno != EINVAL && errno != ENOTTY)
      refused_.push_back(std::string("exposure: cannot switch auto exposure off (") +
                         std::strerror(errno) + ")");
    v4l2_queryctrl query{};
    query.id = V4L2_CID_EXPOSURE_ABSOLUTE;
    if (xioctl(VIDIOC_QUERYCTRL, &query) < 0 || (query.flags & V4L2_CTRL_FLAG_DISABLED)) {
      if (errno == ENODEV) return v4l2_errno_status(device_, "VIDIOC_QUERYCTRL", errno);
      refused_.push_back("exposure: the driver has no V4L2_CID_EXPOSURE_ABSOLUTE control");
      return Status::ok();
    }
    const int wanted = static_cast<int>(std::lround(options_.exposure_us / 100.0));
    const int clamped = std::clamp(wanted, query.minimum, query.maximum);
    v4l2_control exposure{V4L2_CID_EXPOSURE_ABSOLUTE, clamped};
    if (xioctl(VIDIOC_S_CTRL, &exposure) < 0) {
      if (errno == ENODEV) return v4l2_errno_status(device_, "VIDIOC_S_CTRL", errno);
      refused_.push_back(std::string("exposure: the driver refused it (") + std::strerror(errno) +
                         ")");
      return Status::ok();
    }
    v4l2_control readback{V4L2_CID_EXPOSURE_ABSOLUTE, 0};
    if (xioctl(VIDIOC_G_CTRL, &readback) == 0) exposure_100us_ = readback.value;
    if (exposure_100us_ != wanted)
      refused_.push_back("exposure: asked " + std::to_string(options_.exposure_us) +
                         " us, the driver gave " + std::to_string(exposure_100us_ * 100) +
                         " us (range " + std::to_string(query.minimum * 100) + ".." +
                         std::to_string(query.maximum * 100) + " us)");
    return Status::ok();
  }

  Status start_streaming() {
    v4l2_requestbuffers req{};
    req.count = static_cast<uint32_t>(options_.buffer_count);
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    if (xioctl(VIDIOC_REQBUFS, &req) < 0) {
      if (errno == EINVAL) return unsupported(device_ + ": the driver does not support mmap I/O");
      return v4l2_errno_status(device_, "VIDIOC_REQBUFS", errno);
    }
    if (req.count < 2)
      return io_error(device_ + ": the driver gave " + std::to_string(req.count) +
                      " buffer(s); streaming needs at least 2");
    buffers_.resize(req.count);
    for (uint32_t i = 0; i < req.count; ++i) {
      v4l2_buffer buf{};
      buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      buf.memory = V4L2_MEMORY_MMAP;
      buf.index = i;
      if (xioctl(VIDIOC_QUERYBUF, &buf) < 0)
        return v4l2_errno_status(device_, "VIDIOC_QUERYBUF", errno);
      void* data = io_->mmap(buf.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, buf.m.offset);
      if (data == MAP_FAILED) return v4l2_errno_status(device_, "mmap", errno);
      buffers_[i] = {data, buf.length};
    }
    for (uint32_t i = 0; i < req.count; ++i) GVKIT_RETURN_IF_ERROR(queue(i));
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(VIDIOC_STREAMON, &type) < 0)
      return v4l2_errno_status(device_, "VIDIOC_STREAMON", errno);
    streaming_ = true;
    return Status::ok();
  }

  Status queue(uint32_t index) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = index;
    if (xioctl(VIDIOC_QBUF, &buf) < 0) return v4l2_errno_status(device_, "VIDIOC_QBUF", errno);
    return Status::ok();
  }

  // Waits for and dequeues one buffer; EINTR/EAGAIN retried until the timeout.
  Result<v4l2_buffer> dequeue() {
    int io_errors = 0;
    for (;;) {
      const int ready = io_->poll(fd_, options_.timeout_ms);
      if (ready < 0) {
        if (errno == EINTR || errno == EAGAIN) {
          ++counters_.retries;
          continue;
        }
        return v4l2_errno_status(device_, "poll", errno);
      }
      if (ready == 0)
        return io_error(device_ + ": no frame within " + std::to_string(options_.timeout_ms) +
                        " ms");
      v4l2_buffer buf{};
      buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      buf.memory = V4L2_MEMORY_MMAP;
      if (xioctl(VIDIOC_DQBUF, &buf) == 0) {
        if (buf.index >= buffers_.size())
          return io_error(device_ + ": the driver returned buffer " + std::to_string(buf.index) +
                          " of " + std::to_string(buffers_.size()));
        return buf;
      }
      if (errno == EAGAIN) {
        ++counters_.retries;
        continue;
      }
      if (errno == EIO && ++io_errors < kMaxConsecutiveIoErrors) {
        ++counters_.errored;  // the spec's "temporary problem, e.g. signal loss"
        continue;
      }
      return v4l2_errno_status(device_, "VIDIOC_DQBUF", errno);
    }
  }

  // The grey image in a buffer, or an empty Mat when the bytes cannot hold a frame.
  cv::Mat convert(const uint8_t* data, size_t bytes_used) const {
    const int bpp = bytes_per_pixel(fourcc_);
    if (bpp > 0) {
      const size_t needed = stride_ * static_cast<size_t>(height_ - 1) +
                            static_cast<size_t>(width_) * static_cast<size_t>(bpp);
      if (bytes_used < needed) return {};
    }
    switch (fourcc_) {
      case V4L2_PIX_FMT_GREY:
        return cv::Mat(height_, width_, CV_8U, const_cast<uint8_t*>(data), stride_).clone();
      case V4L2_PIX_FMT_Y16:
        if (stride_ % 2 != 0) {  // unaligned rows: copy row by row
          cv::Mat out(height_, width_, CV_16U);
          for (int y = 0; y < height_; ++y)
            std::memcpy(out.ptr(y), data + stride_ * y, static_cast<size_t>(width_) * 2);
          return out;
        }
        return cv::Mat(height_, width_, CV_16U, const_cast<uint8_t*>(data), stride_).clone();
      case V4L2_PIX_FMT_YUYV: {
        cv::Mat out(height_, width_, CV_8U);
        for (int y = 0; y < height_; ++y) {
          const uint8_t* row = data + stride_ * y;
          uint8_t* dst = out.ptr<uint8_t>(y);
          for (int x = 0; x < width_; ++x) dst[x] = row[2 * x];
        }
        return out;
      }
      case V4L2_PIX_FMT_MJPEG: {
        if (bytes_used == 0) return {};
        cv::Mat jpeg(1, static_cast<int>(bytes_used), CV_8U, const_cast<uint8_t*>(data));
        Result<cv::Mat> grey = opencv_media::imdecode(jpeg, cv::IMREAD_GRAYSCALE);
        if (!grey.is_ok() || grey->empty() || grey->cols != width_ || grey->rows != height_)
          return {};
        return std::move(grey).value();
      }
      default:
        return {};
    }
  }

  Result<std::optional<CameraFrame>> next_frame() {
    for (;;) {
      GVKIT_ASSIGN_OR_RETURN(v4l2_buffer buf, dequeue());
      const Timestamp dequeued_at = monotonic_now();
      if (have_sequence_ && buf.sequence > last_sequence_ + 1)
        counters_.dropped += buf.sequence - last_sequence_ - 1;
      if (!have_sequence_ || buf.sequence > last_sequence_) last_sequence_ = buf.sequence;
      have_sequence_ = true;

      cv::Mat image;
      if (!(buf.flags & V4L2_BUF_FLAG_ERROR))
        image = convert(static_cast<const uint8_t*>(buffers_[buf.index].data),
                        std::min<size_t>(buf.bytesused, buffers_[buf.index].length));
      GVKIT_RETURN_IF_ERROR(queue(buf.index));
      if (image.empty()) {
        ++counters_.errored;
        continue;
      }

      Timestamp timestamp = dequeued_at;
      if ((buf.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC)
        timestamp = Timestamp(static_cast<int64_t>(buf.timestamp.tv_sec) * 1000000000 +
                              static_cast<int64_t>(buf.timestamp.tv_usec) * 1000);
      if (have_timestamp_ && timestamp < last_timestamp_) {
        timestamp = last_timestamp_;
        ++counters_.clamped_timestamps;
      }
      last_timestamp_ = timestamp;
      have_timestamp_ = true;

      CameraFrame frame;
      frame.image = std::move(image);
      frame.sequence = buf.sequence;
      frame.timestamp = timestamp;
      frame.exposure = Timestamp(static_cast<int64_t>(exposure_100us_) * 100000);
      ++counters_.frames;
      return std::optional<CameraFrame>(std::move(frame));
    }
  }

  std::string device_;
  std::shared_ptr<V4l2Io> io_;
  FrameSourceOptions options_;
  int fd_ = -1;
  bool streaming_ = false;
  std::string driver_, card_;
  uint32_t fourcc_ = 0;
  int width_ = 0, height_ = 0;
  size_t stride_ = 0, image_bytes_ = 0;
  double fps_ = 0;
  int exposure_100us_ = 0;
  std::vector<MappedBuffer> buffers_;
  std::vector<std::string> refused_;
  bool have_sequence_ = false, have_timestamp_ = false;
  uint32_t last_sequence_ = 0;
  Timestamp last_timestamp_{0};
  Status failure_;
  FrameSourceCounters counters_;
};

}  // namespace

std::string fourcc_name(uint32_t fourcc) {
  std::string name;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xff);
    if (c == ' ' || c == '\0') continue;
    name += (c >= 0x21 && c < 0x7f) ? c : '?';
  }
  return name;
}

Result<std::unique_ptr<FrameSource>> open_v4l2_source(const std::string& device,
                                                      const FrameSourceOptions& options,
                                                      std::shared_ptr<V4l2Io> io) {
  GVKIT_CHECK(io != nullptr, "open_v4l2_source without an I/O seam");
  GVKIT_RETURN_IF_ERROR(options.check());
  auto source = std::make_unique<V4l2Source>(device, std::move(io), options);
  GVKIT_RETURN_IF_ERROR(source->open());
  return std::unique_ptr<FrameSource>(std::move(source));
}

Result<std::unique_ptr<FrameSource>> open_v4l2_source(const std::string& device,
                                                      const FrameSourceOptions& options) {
  return open_v4l2_source(device, options, make_system_v4l2_io());
}

}  // namespace gvkit
