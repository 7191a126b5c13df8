#pragma once
// A fake V4L2 capture driver behind the V4l2Io seam: it answers the ioctls the V4L2 source and
// the device listing make, and plays a script of events (frames with chosen sequence numbers,
// timestamps and flags; errno values such as EAGAIN, EINTR, ENODEV) so tests can inject what
// real drivers do.

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <deque>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "gvkit/capture/v4l2_io.hpp"

namespace gvkit::testing {

struct FakeEvent {
  enum Kind { kFrame, kPollErrno, kDqbufErrno, kVanish } kind = kFrame;
  int error = 0;          // for the errno kinds
  uint32_t sequence = 0;  // for frames
  int64_t timestamp_ns = 0;
  uint32_t flags = 0;       // extra buffer flags (V4L2_BUF_FLAG_ERROR, ...)
  int64_t bytes_used = -1;  // -1 = a whole frame
};

class FakeV4l2Driver : public V4l2Io {
 public:
  // --- configuration, set before the source opens the device ---
  std::string path = "/dev/video7";
  int open_errno = 0;
  uint32_t capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  std::vector<uint32_t> formats = {V4L2_PIX_FMT_GREY, V4L2_PIX_FMT_YUYV};
  std::map<uint32_t, uint32_t> s_fmt_substitutes;  // asked -> what S_FMT answers instead
  uint32_t pixelformat = V4L2_PIX_FMT_GREY;
  int width = 33, height = 7;
  int stride_padding = 7;  // bytesperline = width * bpp + padding
  bool can_set_fps = true;
  double fps = 30, max_fps = 60;
  bool has_exposure = true;
  int exposure_min = 1, exposure_max = 500, exposure = 100;  // 100 us units
  bool timestamps_monotonic = true;
  std::deque<FakeEvent> script;

  // --- what happened ---
  bool opened = false, closed = false, streaming = false, stream_off = false;
  int mapped = 0, unmapped = 0;
  int exposure_mode = V4L2_EXPOSURE_APERTURE_PRIORITY;

  static int bytes_per_pixel(uint32_t f) {
    return f == V4L2_PIX_FMT_GREY ? 1 : (f == V4L2_PIX_FMT_MJPEG ? 0 : 2);
  }
  int stride() const {
    return bytes_per_pixel(pixelformat) == 0
               ? 0
               : width * bytes_per_pixel(pixelformat) + stride_padding;
  }
  size_t image_bytes() const {
    return pixelformat == V4L2_PIX_FMT_MJPEG ? static_cast<size_t>(width * height * 4 + 4096)
                                             : static_cast<size_t>(stride()) * height;
  }

  // The grey image of frame `sequence` (what the source must deliver).
  cv::Mat expected(uint32_t sequence) const {
    const bool sixteen = pixelformat == V4L2_PIX_FMT_Y16;
    cv::Mat image(height, width, sixteen ? CV_16U : CV_8U);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const int v = x * 5 + y * 11 + static_cast<int>(sequence) * 3;
        if (sixteen)
          image.at<uint16_t>(y, x) = static_cast<uint16_t>(v * 97 + 1);
        else
          image.at<uint8_t>(y, x) = static_cast<uint8_t>(v & 0xff);
      }
    return image;
  }

  int open(const std::string& p, int) override {
    if (open_errno) return fail(open_errno);
    if (p != path) return fail(ENOENT);
    opened = true;
    return 42;
  }
  int close(int) override {
    closed = true;
    return 0;
  }
  void* mmap(size_t length, int, int, int, int64_t offset) override {
    const size_t index = static_cast<size_t>(offset) / kOffsetStep;
    if (index >= buffers_.size() || length != buffers_[index].size()) {
      errno = EINVAL;
      return MAP_FAILED;
    }
    ++mapped;
    return buffers_[index].data();
  }
  int munmap(void*, size_t) override {
    ++unmapped;
    return 0;
  }
  int poll(int, int) override {
    if (vanished_) return fail(ENODEV);
    if (!script.empty() && script.front().kind == FakeEvent::kPollErrno) {
      const int e = script.front().error;
      script.pop_front();
      return fail(e);
    }
    return script.empty() ? 0 : 1;
  }

  int ioctl(int, unsigned long request, void* arg) override {
    if (vanished_) return fail(ENODEV);
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* cap = static_cast<v4l2_capability*>(arg);
        std::memset(cap, 0, sizeof(*cap));
        std::strcpy(reinterpret_cast<char*>(cap->driver), "fakecam");
        std::strcpy(reinterpret_cast<char*>(cap->card), "Fake Camera");
        std::strcpy(reinterpret_cast<char*>(cap->bus_info), "platform:fake");
        cap->capabilities = capabilities | V4L2_CAP_DEVICE_CAPS;
        cap->device_caps = capabilities;
        return 0;
      }
      case VIDIOC_ENUM_FMT: {
        auto* d = static_cast<v4l2_fmtdesc*>(arg);
        if (d->index >= formats.size()) return fail(EINVAL);
        d->pixelformat = formats[d->index];
        std::snprintf(reinterpret_cast<char*>(d->description), sizeof(d->description),
                      "fake format %u", d->index);
        return 0;
      }
      case VIDIOC_ENUM_FRAMESIZES: {
        auto* s = static_cast<v4l2_frmsizeenum*>(arg);
        if (s->index >= 2) return fail(EINVAL);
        s->type = V4L2_FRMSIZE_TYPE_DISCRETE;
        s->discrete.width = s->index == 0 ? 640 : 1280;
        s->discrete.height = s->index == 0 ? 480 : 720;
        return 0;
      }
      case VIDIOC_ENUM_FRAMEINTERVALS: {
        auto* i = static_cast<v4l2_frmivalenum*>(arg);
        if (i->index >= 2) return fail(EINVAL);
        i->type = V4L2_FRMIVAL_TYPE_DISCRETE;
        i->discrete.numerator = 1;
        i->discrete.denominator = i->index == 0 ? 30 : 60;
        return 0;
      }
      case VIDIOC_G_FMT:
      case VIDIOC_S_FMT: {
        auto* f = static_cast<v4l2_format*>(arg);
        if (request == VIDIOC_S_FMT) {
          uint32_t asked = f->fmt.pix.pixelformat;
          if (s_fmt_substitutes.count(asked)) asked = s_fmt_substitutes[asked];
          if (asked == 0) return fail(EINVAL);
          pixelformat = asked;
          if (f->fmt.pix.width > 0) width = static_cast<int>(std::min(f->fmt.pix.width, 64u));
          if (f->fmt.pix.height > 0) height = static_cast<int>(std::min(f->fmt.pix.height, 48u));
        }
        std::memset(&f->fmt.pix, 0, sizeof(f->fmt.pix));
        f->fmt.pix.pixelformat = pixelformat;
        f->fmt.pix.width = static_cast<uint32_t>(width);
        f->fmt.pix.height = static_cast<uint32_t>(height);
        f->fmt.pix.bytesperline = static_cast<uint32_t>(stride());
        f->fmt.pix.sizeimage = static_cast<uint32_t>(image_bytes());
        return 0;
      }
      case VIDIOC_G_PARM:
      case VIDIOC_S_PARM: {
        auto* p = static_cast<v4l2_streamparm*>(arg);
        if (request == VIDIOC_S_PARM) {
          if (!can_set_fps) return fail(EINVAL);
          const auto& t = p->parm.capture.timeperframe;
          fps = std::min(max_fps, static_cast<double>(t.denominator) / t.numerator);
        }
        std::memset(&p->parm, 0, sizeof(p->parm));
        p->parm.capture.capability = can_set_fps ? V4L2_CAP_TIMEPERFRAME : 0;
        p->parm.capture.timeperframe = {1000, static_cast<uint32_t>(fps * 1000)};
        return 0;
      }
      case VIDIOC_QUERYCTRL: {
        auto* q = static_cast<v4l2_queryctrl*>(arg);
        if (!has_exposure || q->id != V4L2_CID_EXPOSURE_ABSOLUTE) return fail(EINVAL);
        q->minimum = exposure_min;
        q->maximum = exposure_max;
        q->step = 1;
        return 0;
      }
      case VIDIOC_S_CTRL:
      case VIDIOC_G_CTRL: {
        auto* c = static_cast<v4l2_control*>(arg);
        if (!has_exposure) return fail(EINVAL);
        if (c->id == V4L2_CID_EXPOSURE_AUTO) {
          if (request == VIDIOC_S_CTRL) exposure_mode = c->value;
          return 0;
        }
        if (c->id != V4L2_CID_EXPOSURE_ABSOLUTE) return fail(EINVAL);
        if (request == VIDIOC_S_CTRL) {
          if (c->value < exposure_min || c->value > exposure_max) return fail(ERANGE);
          exposure = c->value;
        } else {
          c->value = exposure;
        }
        return 0;
      }
      case VIDIOC_REQBUFS: {
        auto* r = static_cast<v4l2_requestbuffers*>(arg);
        if (r->memory != V4L2_MEMORY_MMAP) return fail(EINVAL);
        r->count = std::min<uint32_t>(r->count, 6);
        buffers_.assign(r->count, std::vector<uint8_t>(image_bytes(), 0xEE));
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffers_.size()) return fail(EINVAL);
        b->length = static_cast<uint32_t>(buffers_[b->index].size());
        b->m.offset = static_cast<uint32_t>(b->index * kOffsetStep);
        return 0;
      }
      case VIDIOC_QBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffers_.size() || queued_.count(b->index)) return fail(EINVAL);
        queued_.insert(b->index);
        order_.push_back(b->index);
        return 0;
      }
      case VIDIOC_STREAMON:
        streaming = true;
        return 0;
      case VIDIOC_STREAMOFF:
        stream_off = true;
        streaming = false;
        return 0;
      case VIDIOC_DQBUF:
        return dequeue(static_cast<v4l2_buffer*>(arg));
      default:
        return fail(ENOTTY);
    }
  }

 private:
  static constexpr size_t kOffsetStep = 1 << 20;

  static int fail(int e) {
    errno = e;
    return -1;
  }

  void fill(std::vector<uint8_t>& buffer, uint32_t sequence, size_t* used) const {
    const cv::Mat image = expected(sequence);
    std::fill(buffer.begin(), buffer.end(), 0xEE);  // padding must never show
    if (pixelformat == V4L2_PIX_FMT_MJPEG) {
      std::vector<uint8_t> jpeg;
      cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 100});
      std::memcpy(buffer.data(), jpeg.data(), std::min(jpeg.size(), buffer.size()));
      *used = jpeg.size();
      return;
    }
    for (int y = 0; y < height; ++y) {
      uint8_t* row = buffer.data() + static_cast<size_t>(stride()) * y;
      for (int x = 0; x < width; ++x) {
        if (pixelformat == V4L2_PIX_FMT_GREY) {
          row[x] = image.at<uint8_t>(y, x);
        } else if (pixelformat == V4L2_PIX_FMT_Y16) {
          const uint16_t v = image.at<uint16_t>(y, x);
          row[2 * x] = static_cast<uint8_t>(v & 0xff);
          row[2 * x + 1] = static_cast<uint8_t>(v >> 8);
        } else {  // YUYV: luma, then alternating chroma
          row[2 * x] = image.at<uint8_t>(y, x);
          row[2 * x + 1] = static_cast<uint8_t>(x % 2 ? 0x30 : 0xC0);
        }
      }
    }
    *used = image_bytes();
  }

  int dequeue(v4l2_buffer* b) {
    if (script.empty() || order_.empty()) return fail(EAGAIN);
    const FakeEvent event = script.front();
    script.pop_front();
    switch (event.kind) {
      case FakeEvent::kDqbufErrno:
        return fail(event.error);
      case FakeEvent::kVanish:
        vanished_ = true;
        return fail(ENODEV);
      case FakeEvent::kPollErrno:
        return fail(EAGAIN);
      case FakeEvent::kFrame:
        break;
    }
    const uint32_t index = order_.front();
    order_.pop_front();
    queued_.erase(index);
    size_t used = 0;
    fill(buffers_[index], event.sequence, &used);
    b->index = index;
    b->bytesused = static_cast<uint32_t>(event.bytes_used >= 0 ? event.bytes_used : used);
    b->sequence = event.sequence;
    b->flags = event.flags | V4L2_BUF_FLAG_DONE |
               (timestamps_monotonic ? V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC
                                     : V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN);
    b->timestamp.tv_sec = event.timestamp_ns / 1000000000;
    b->timestamp.tv_usec = (event.timestamp_ns % 1000000000) / 1000;
    return 0;
  }

  bool vanished_ = false;
  std::vector<std::vector<uint8_t>> buffers_;
  std::set<uint32_t> queued_;
  std::deque<uint32_t> order_;
};

// n frames, sequence from first_sequence, 1/30 s apart.
inline std::deque<FakeEvent> frames(int n, uint32_t first_sequence = 0) {
  std::deque<FakeEvent> events;
  for (int i = 0; i < n; ++i) {
    FakeEvent e;
    e.sequence = first_sequence + static_cast<uint32_t>(i);
    e.timestamp_ns = 1'000'000'000 + static_cast<int64_t>(e.sequence) * 33'333'333;
    events.push_back(e);
  }
  return events;
}

}  // namespace gvkit::testing
