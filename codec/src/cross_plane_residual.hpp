#pragma once
// Cross-plane residual prediction (format 1.6, docs/bitstream.md 4.9): the spatial-domain
// residual of a coded macroblock, which the X plane keeps for the Y and Z planes.

#include <cstdint>

#include "gvkit/codec/cross_plane.hpp"
#include "macroblock_syntax.hpp"

namespace gvkit::codec::detail {

// The residual the macroblock's levels add to its prediction (16x16, row-major, sample units):
// what reconstruct_block adds (before clipping), without any cross-plane term. Zero for a skip.
void macroblock_residual(const MacroblockData& mb, const PlaneCodingParams& p, int32_t* out);

// Stores the macroblock's reconstructed residual into `out`, and whether it is nonzero: its
// decoded residual (macroblock_residual) plus, when the plane predicts from `source` (may be
// null), the cross-plane term of the macroblock's scale.
void record_macroblock_residual(CrossPlaneResidual& out, int mb_x, int mb_y,
                                const MacroblockData& mb, const PlaneCodingParams& p,
                                const CrossPlaneResidual* source);

}  // namespace gvkit::codec::detail
