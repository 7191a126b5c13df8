#include "tool_support.hpp"

#include <cstdio>

namespace gvkit::tools {

Result<std::pair<int, int>> parse_size(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') ||
      w <= 0 || h <= 0)
    return invalid_argument("size '" + text + "' is not WxH (e.g. 640x480)");
  return std::make_pair(w, h);
}

Status failures_status(const std::vector<std::string>& failures, size_t total) {
  if (failures.empty()) return Status::ok();
  std::string message = std::to_string(failures.size()) + " of " + std::to_string(total) +
                        " frames failed (the others were written): ";
  for (size_t i = 0; i < failures.size() && i < 5; ++i) message += (i ? "; " : "") + failures[i];
  if (failures.size() > 5) message += "; ...";
  return corrupt_data(message);
}

}  // namespace gvkit::tools
