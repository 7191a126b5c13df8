#pragma once
// The camera flags `gvkit record` and `gvkit capture` share (--size, --exposure-us,
// --pixel-format, --buffers), bound to one struct and turned into FrameSourceOptions.

#include <string>

#include <CLI/CLI.hpp>

#include "gvkit/capture/frame_source.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::tools {

struct SourceArgs {
  std::string size;  // WxH, empty = the device's current size
  double exposure_us = 0;
  std::string pixel_format = "auto";
  int buffers = 4;
};

// Adds --size, --exposure-us, --pixel-format and --buffers to cmd, bound to args.
void add_source_flags(CLI::App* cmd, SourceArgs& args, const std::string& size_help);

// The FrameSourceOptions of the flags (fps and the rest left at their defaults). Fails naming
// the flag on a malformed size.
Result<FrameSourceOptions> frame_source_options(const SourceArgs& args);

}  // namespace gvkit::tools
