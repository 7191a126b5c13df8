#pragma once
// Rate-distortion optimised quantization (encoder only, lossy planes; no syntax of its own): the
// levels of one transform block chosen to minimise D + lambda R instead of by a fixed rounding
// offset, as HEVC's reference encoder (RDOQ) and x264's trellis do.
//
// Per coefficient, in the order the levels are coded (reverse scan from the last coefficient
// the nearest rounding makes nonzero), the level is the cheapest of the nearest rounding, one
// less, and zero; then the last significant position is the cheapest of every nonzero one (or
// none: the block all zero). D is the squared reconstruction error in sample units of the coded
// bit depth: the 4x4, 8x8 and 16x16 transforms with their quantizers have one step,
// quantizer_step(qp'), in every position of the orthonormal transform, so a level off the
// unrounded magnitude q by e costs (e x step)^2. R is the CABAC bits of the block's
// significance map, levels and signs (write_residual in macroblock_syntax.hpp) estimated from
// the contexts' current states; the states are not advanced within the block, and the level
// contexts follow the levels already decided.

#include <cstdint>

#include "macroblock_syntax.hpp"

namespace gvkit::codec::detail {

// levels (n x n, raster order, n = 4, 8 or 16) of the forward-transform coefficients `coeffs`
// (raster order; forward_transform4x4 / 8x8 / 16x16's output) at qp_prime (0..99) with
// `lambda` (per bit, in squared sample units) and the contexts `ctx` of the block's residual
// category. May return all zero. Not for lossless planes or adaptive level coding (contract).
void quantize_rdo(int n, const int32_t* coeffs, int qp_prime, double lambda, const ContextSet& ctx,
                  int32_t* levels);

}  // namespace gvkit::codec::detail
