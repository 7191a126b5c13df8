#include "gvkit/capture/v4l2_devices.hpp"

#include <fcntl.h>
#include <linux/videodev2.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <filesystem>

#include "gvkit/capture/v4l2_source.hpp"
#include "v4l2_errors.hpp"

namespace gvkit {
namespace {

std::string size_text(uint32_t w, uint32_t h) {
  return std::to_string(w) + "x" + std::to_string(h);
}

std::string fps_text(const v4l2_fract& interval) {
  if (interval.numerator == 0) return "?";
  char text[32];
  std::snprintf(text, sizeof(text), "%.4g",
                static_cast<double>(interval.denominator) / interval.numerator);
  return text;
}

std::vector<std::string> frame_rates(V4l2Io& io, int fd, uint32_t fourcc, uint32_t w, uint32_t h) {
  std::vector<std::string> rates;
  for (uint32_t i = 0; i < 64; ++i) {
    v4l2_frmivalenum e{};
    e.index = i;
    e.pixel_format = fourcc;
    e.width = w;
    e.height = h;
    if (io.ioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &e) < 0) break;
    if (e.type == V4L2_FRMIVAL_TYPE_DISCRETE) {
      rates.push_back(fps_text(e.discrete) + " fps");
    } else {  // intervals: max interval = min fps
      rates.push_back(fps_text(e.stepwise.max) + ".." + fps_text(e.stepwise.min) + " fps");
      break;
    }
  }
  return rates;
}

}  // namespace

std::vector<std::string> find_v4l2_device_paths(const std::string& dev_dir) {
  std::vector<std::pair<int, std::string>> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dev_dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("video", 0) != 0 || name.size() == 5) continue;
    const std::string number = name.substr(5);
    if (number.find_first_not_of("0123456789") != std::string::npos) continue;
    found.emplace_back(std::stoi(number), entry.path().string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> paths;
  for (auto& f : found) paths.push_back(f.second);
  return paths;
}

Result<V4l2DeviceInfo> query_v4l2_device(const std::string& path, V4l2Io& io) {
  const int fd = io.open(path, O_RDWR | O_NONBLOCK);
  if (fd < 0) return detail::v4l2_errno_status(path, "open", errno);
  struct Closer {
    V4l2Io& io;
    int fd;
    ~Closer() { io.close(fd); }
  } closer{io, fd};

  V4l2DeviceInfo info;
  info.path = path;
  v4l2_capability cap{};
  if (io.ioctl(fd, VIDIOC_QUERYCAP, &cap) < 0)
    return detail::v4l2_errno_status(path, "VIDIOC_QUERYCAP", errno);
  info.driver = reinterpret_cast<const char*>(cap.driver);
  info.card = reinterpret_cast<const char*>(cap.card);
  info.bus = reinterpret_cast<const char*>(cap.bus_info);
  const uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  info.capture = (caps & V4L2_CAP_VIDEO_CAPTURE) && (caps & V4L2_CAP_STREAMING);
  if (!info.capture) return info;

  for (uint32_t f = 0; f < 256; ++f) {
    v4l2_fmtdesc desc{};
    desc.index = f;
    desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (io.ioctl(fd, VIDIOC_ENUM_FMT, &desc) < 0) break;
    V4l2FormatInfo format;
    format.fourcc = fourcc_name(desc.pixelformat);
    format.description = reinterpret_cast<const char*>(desc.description);
    format.readable =
        desc.pixelformat == V4L2_PIX_FMT_GREY || desc.pixelformat == V4L2_PIX_FMT_Y16 ||
        desc.pixelformat == V4L2_PIX_FMT_YUYV || desc.pixelformat == V4L2_PIX_FMT_MJPEG;
    for (uint32_t s = 0; s < 256; ++s) {
      v4l2_frmsizeenum size{};
      size.index = s;
      size.pixel_format = desc.pixelformat;
      if (io.ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &size) < 0) break;
      if (size.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
        format.sizes.push_back(
            {size_text(size.discrete.width, size.discrete.height),
             frame_rates(io, fd, desc.pixelformat, size.discrete.width, size.discrete.height)});
      } else {
        const auto& w = size.stepwise;
        format.sizes.push_back({size_text(w.min_width, w.min_height) + ".." +
                                    size_text(w.max_width, w.max_height) + " step " +
                                    size_text(w.step_width, w.step_height),
                                frame_rates(io, fd, desc.pixelformat, w.max_width, w.max_height)});
        break;
      }
    }
    info.formats.push_back(std::move(format));
  }
  return info;
}

}  // namespace gvkit
