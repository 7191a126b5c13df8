#include "source_args.hpp"

#include <cstdio>

namespace gvkit::tools {

void add_source_flags(CLI::App* cmd, SourceArgs& args, const std::string& size_help) {
  cmd->add_option("--size", args.size, size_help);
  cmd->add_option("--exposure-us", args.exposure_us, "Manual exposure in microseconds");
  cmd->add_option("--pixel-format", args.pixel_format, "auto, GREY, Y16, YUYV or MJPG")
      ->capture_default_str();
  cmd->add_option("--buffers", args.buffers, "Driver buffers (2..32)")->capture_default_str();
}

Result<FrameSourceOptions> frame_source_options(const SourceArgs& args) {
  FrameSourceOptions so;
  if (!args.size.empty()) {
    int w = 0, h = 0;
    char tail = 0;
    if (std::sscanf(args.size.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w <= 0 || h <= 0)
      return invalid_argument("--size '" + args.size + "': expected WxH, e.g. 640x480");
    so.width = w;
    so.height = h;
  }
  so.exposure_us = args.exposure_us;
  so.pixel_format = args.pixel_format;
  so.buffer_count = args.buffers;
  return so;
}

}  // namespace gvkit::tools
