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

// quantize_rdo's choice of the last significant position among n scan positions: of the j with
// chosen[j] != 0, the one with the lowest total before(j) + chosen_cost[j] + last_extra[j] +
// after[j], where before(j) is chosen_cost[0] + ... + chosen_cost[j - 1] summed in that order
// (after[j]: the distortion of leaving out every coefficient after j); of equal totals the
// latest; -1 when no total is below all_zero (the block coded as all zero). One forward pass.
int last_significant_position(int n, const int32_t* chosen, const double* chosen_cost,
                              const double* last_extra, const double* after, double all_zero);
// The same by a pass of prefix sums and a backward search, the plain form it replaced (kept to
// check it: the same position for any input).
int last_significant_position_reference(int n, const int32_t* chosen, const double* chosen_cost,
                                        const double* last_extra, const double* after,
                                        double all_zero);

}  // namespace gvkit::codec::detail
