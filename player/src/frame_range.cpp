#include "gvkit/player/frame_range.hpp"

#include <algorithm>
#include <cctype>

namespace gvkit::player {
namespace {

// Non-negative integer; empty text gives `empty_value`.
Result<int64_t> parse_index(const std::string& s, int64_t empty_value, const std::string& whole) {
  if (s.empty()) return empty_value;
  if (s.size() > 15 ||
      !std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); }))
    return invalid_argument("frame range '" + whole + "': '" + s +
                            "' is not a frame number (use A:B, A:, :B or N)");
  return static_cast<int64_t>(std::stoll(s));
}

}  // namespace

Result<FrameRange> parse_frame_range(const std::string& text) {
  FrameRange r;
  const auto colon = text.find(':');
  if (colon == std::string::npos) {
    if (text.empty()) return invalid_argument("empty frame range (use A:B, A:, :B or N)");
    GVKIT_ASSIGN_OR_RETURN(r.begin, parse_index(text, 0, text));
    r.end = r.begin + 1;
    return r;
  }
  GVKIT_ASSIGN_OR_RETURN(r.begin, parse_index(text.substr(0, colon), 0, text));
  GVKIT_ASSIGN_OR_RETURN(r.end, parse_index(text.substr(colon + 1), -1, text));
  if (r.end >= 0 && r.end <= r.begin)
    return invalid_argument("frame range '" + text + "' is empty (B must be greater than A)");
  return r;
}

Result<std::vector<int64_t>> FrameRange::indices(int64_t frame_count) const {
  const int64_t last = end < 0 ? frame_count : std::min(end, frame_count);
  if (begin >= last)
    return invalid_argument("frame range " + std::to_string(begin) + ":" +
                            (end < 0 ? std::string() : std::to_string(end)) +
                            " selects no frame of a " + std::to_string(frame_count) +
                            "-frame sequence");
  std::vector<int64_t> out;
  for (int64_t i = begin; i < last; ++i) out.push_back(i);
  return out;
}

}  // namespace gvkit::player
