#pragma once
// What the V4L2 devices of this machine can do, for `gvkit devices`: driver, card, and per pixel
// format the frame sizes and frame rates (VIDIOC_ENUM_FMT / ENUM_FRAMESIZES /
// ENUM_FRAMEINTERVALS).

#include <memory>
#include <string>
#include <vector>

#include "gvkit/capture/v4l2_io.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit {

struct V4l2FrameSize {
  std::string size;                // "640x480", or a range "16x16..1920x1080 step 2x2"
  std::vector<std::string> rates;  // "30 fps", or a range "1..60 fps"; empty when unknown
};

struct V4l2FormatInfo {
  std::string fourcc;       // "GREY"
  std::string description;  // the driver's words
  bool readable = false;    // gvkit's V4L2 source reads it
  std::vector<V4l2FrameSize> sizes;
};

struct V4l2DeviceInfo {
  std::string path, driver, card, bus;
  bool capture = false;  // a streaming video capture node (metadata nodes are not)
  std::vector<V4l2FormatInfo> formats;
};

// /dev/video* in numeric order (empty when there are none).
std::vector<std::string> find_v4l2_device_paths(const std::string& dev_dir = "/dev");

// Queries one device. Fails naming it when it cannot be opened (missing, permission, busy) or
// is not a V4L2 device.
Result<V4l2DeviceInfo> query_v4l2_device(const std::string& path, V4l2Io& io);

}  // namespace gvkit
