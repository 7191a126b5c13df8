#pragma once
// In-loop deblocking filter of a reconstructed plane (format 1.8, docs/bitstream.md 4.12).
// HEVC's normal luma filter on the 8x8 grid, with thresholds that scale with the plane's
// quantizer step instead of HEVC's tables: a geometry image is a smooth surface sampled at
// 16 bits, whose blocking shows at QPs where H.264's and HEVC's tables do not filter at all.
// Per line across an edge (p2 p1 p0 | q0 q1 q2):
//   filtered when |p2 - 2 p1 + p0| + |q2 - 2 q1 + q0| < beta (both sides smooth) and
//   |delta| < 10 tc, delta = (9 (q0 - p0) - 3 (q1 - p1) + 8) >> 4 (the step between the sides
//   that a straight line through p1, p0, q0, q1 would not have; 0 on any linear ramp);
//   p0 += clip(delta, +-tc), q0 -= the same; p1 and q1 move by at most tc / 2 where their own
//   side is smoother still (< 3 beta / 16).
// All vertical edges of the plane are filtered first (left to right, top to bottom), then all
// horizontal ones; the decoder does exactly what the encoder did, after the plane's last
// macroblock (intra prediction inside the plane reads the samples before filtering).

#include <cstdint>
#include <vector>

#include "gvkit/codec/plane_coding.hpp"

namespace gvkit::codec {

// Boundary strengths of a plane's edges per 4x4 block: vertical[i] is the strength of block i's
// left edge, horizontal[i] of its top edge (raster order, blocks_x x blocks_y blocks); 0 = not
// filtered, 1 = filtered with tc, 2 = with 2 tc. Only blocks at an even column (vertical) or
// row (horizontal) other than the first are read: the 8x8 grid inside the plane.
struct DeblockingStrengths {
  int blocks_x = 0, blocks_y = 0;
  std::vector<uint8_t> vertical, horizontal;
  void reset(int bx, int by) {
    blocks_x = bx;
    blocks_y = by;
    vertical.assign(static_cast<size_t>(bx) * by, 0);
    horizontal.assign(vertical.size(), 0);
  }
};

// 16 x the quantizer step of qp_prime (0..99) in samples, as an exact integer: {10, 11, 13, 14,
// 16, 18}[qp' mod 6] << (qp' / 6) (0.625 x 2^(qp'/6) to within 4 %).
int64_t deblocking_step16(int qp_prime);

// Filters `plane` in place (width and height multiples of 8; strengths of its 4x4 blocks) with
// the thresholds of qp_prime and params (deblocking_params.hpp), samples kept in [0, 2^bit_depth -
// 1].
// Uses AVX2 where the processor has it (eight lines at a time); the same samples as
// deblock_plane_reference, the plain line-by-line filter.
void deblock_plane(SamplePlane& plane, const DeblockingStrengths& strengths, int qp_prime,
                   int bit_depth, const DeblockingParams& params);
void deblock_plane_reference(SamplePlane& plane, const DeblockingStrengths& strengths, int qp_prime,
                             int bit_depth, const DeblockingParams& params);

}  // namespace gvkit::codec
