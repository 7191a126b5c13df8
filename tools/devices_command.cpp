// gvkit devices: the cameras this machine offers, through V4L2 and libcamera, with their pixel
// formats, frame sizes and frame rates.
#include <cstdio>
#include <string>

#include "command.hpp"
#include "gvkit/capture/libcamera_source.hpp"
#include "gvkit/capture/v4l2_devices.hpp"

namespace gvkit::tools {
namespace {

void list_v4l2(const std::string& dev_dir) {
  const std::vector<std::string> paths = find_v4l2_device_paths(dev_dir);
  std::printf("V4L2 devices:\n");
  if (paths.empty()) {
    std::printf("  none: no %s/video* device nodes\n", dev_dir.c_str());
    return;
  }
  auto io = make_system_v4l2_io(/*use_libv4l2=*/false);
  for (const std::string& path : paths) {
    Result<V4l2DeviceInfo> info = query_v4l2_device(path, *io);
    if (!info.is_ok()) {
      std::printf("  %s\n", info.status().message().c_str());
      continue;
    }
    std::printf("  %s  %s '%s' (%s)%s\n", path.c_str(), info->driver.c_str(), info->card.c_str(),
                info->bus.c_str(), info->capture ? "" : "  [not a capture node]");
    for (const V4l2FormatInfo& format : info->formats) {
      std::printf("    %-5s %s%s\n", format.fourcc.c_str(), format.description.c_str(),
                  format.readable ? "" : "  [gvkit does not read this format]");
      for (const V4l2FrameSize& size : format.sizes) {
        std::string rates;
        for (const std::string& r : size.rates) rates += (rates.empty() ? "" : ", ") + r;
        std::printf("      %s%s%s\n", size.size.c_str(), rates.empty() ? "" : ": ", rates.c_str());
      }
    }
  }
}

void list_libcamera() {
  std::printf("libcamera cameras:\n");
  Result<std::vector<LibcameraCameraInfo>> cameras = list_libcamera_cameras();
  if (!cameras.is_ok()) {
    std::printf("  unavailable: %s\n", cameras.status().message().c_str());
    return;
  }
  if (cameras->empty()) {
    std::printf("  none: libcamera sees no cameras\n");
    return;
  }
  for (size_t i = 0; i < cameras->size(); ++i) {
    const LibcameraCameraInfo& c = (*cameras)[i];
    std::printf("  [%zu] %s%s%s\n", i, c.id.c_str(), c.model.empty() ? "" : "  model ",
                c.model.c_str());
    for (const std::string& f : c.formats) std::printf("    %s\n", f.c_str());
  }
}

}  // namespace

void add_devices_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "devices", "List the cameras (V4L2 devices and libcamera cameras) with their formats");
  auto dev_dir = std::make_shared<std::string>("/dev");
  cmd->add_option("--dev-dir", *dev_dir, "Folder holding the video* device nodes")
      ->capture_default_str();
  cmd->callback([dev_dir] {
    list_v4l2(*dev_dir);
    list_libcamera();
  });
}

}  // namespace gvkit::tools
