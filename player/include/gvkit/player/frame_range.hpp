#pragma once
// Frame selections of the CLI: "A:B" is frames A..B-1 (half-open, like Python slices); either
// side may be left out ("10:", ":20", ":" = all); "N" alone is the single frame N.

#include <cstdint>
#include <string>
#include <vector>

#include "gvkit/core/status.hpp"

namespace gvkit::player {

struct FrameRange {
  int64_t begin = 0;
  int64_t end = -1;  // exclusive; -1 = to the end of the sequence

  // The selected indices within a sequence of frame_count frames. Fails when the range selects
  // nothing (begin beyond the end, or end <= begin).
  Result<std::vector<int64_t>> indices(int64_t frame_count) const;
};

// Parses "A:B", "A:", ":B", ":", "N". Fails naming the text on anything else or negatives.
Result<FrameRange> parse_frame_range(const std::string& text);

}  // namespace gvkit::player
