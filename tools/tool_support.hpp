#pragma once
// Small helpers shared by the player subcommands (render, export, play).

#include <string>
#include <utility>
#include <vector>

#include "gvkit/core/status.hpp"

namespace gvkit::tools {

// "640x480" -> (640, 480). Fails naming the text.
Result<std::pair<int, int>> parse_size(const std::string& text);

// Ok when no frame failed; else "K of N frames failed: <first messages>" (corrupt data).
Status failures_status(const std::vector<std::string>& failures, size_t total);

}  // namespace gvkit::tools
