#pragma once
// Cross-plane contexts (format 1.7, flags2 bit 4, docs/bitstream.md 4.10): the Y and Z planes of
// a frame start their CABAC contexts from the states the X plane's contexts reached at the end
// of its segment, instead of from p = 0.5, since the three coordinates of one geometry image
// share their parameterization and mostly take the same decisions: what X's contexts learnt
// about the frame's skips, types, coded blocks, levels and vectors is a better start than no
// knowledge (a 320x320 plane has only 400 macroblocks to learn from). X is coded first; its
// final states are decoder-side information, so the tool adds no syntax element.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "gvkit/codec/cabac_context.hpp"

namespace gvkit::codec {

// The adaptive state of a coded plane's segment after its last macroblock: every context of the
// macroblock layer (in the codec's fixed order; empty until a plane is recorded into it) and the
// running level means of adaptive level coding (lossless planes, docs/bitstream.md 4.2).
struct CrossPlaneContextStates {
  std::vector<CabacContext> contexts;
  uint32_t level_mean16[3] = {};
};

}  // namespace gvkit::codec
