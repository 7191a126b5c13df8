#pragma once
// The quadratic 16x16 intra mode (format 1.13, docs/bitstream.md 6.1). Geometry images are
// smooth but curved: the I16x16 plane mode extrapolates a plane from one row and one column,
// which misses the surface's curvature by ~curvature x 16^2 at the far corner. This mode fits
// q(x, y) = c0 + c1 x + c2 y + c3 x^2 + c4 y^2 + c5 x y by least squares to the two rows above
// (x = -2 .. 15) and the two columns left (y = 0 .. 15) of the block and predicts q over it.

#include <cstdint>

namespace gvkit::codec {

// Neighbours the fit reads: rows y = -2, -1 for x = -2 .. 15, then columns x = -2, -1 for
// y = 0 .. 15 (block coordinates).
inline constexpr int kQuadraticNeighbours = 68;
// Its I16x16 mode number (after H.264's vertical, horizontal, DC and plane, 0..3).
inline constexpr int kIntra16x16Quadratic = 4;

// Predicts the 16x16 block at (x0, y0) of a plane (row stride `stride`) into out (row-major),
// each value clipped to [0, max_value]. Needs x0 >= 2 and y0 >= 2 (contract): the samples
// above and left of the block must exist (and, for a decoder, be reconstructed). Integer
// arithmetic only: with b the sample at (x0 - 1, y0 - 1) and s_k the neighbours minus b,
// c_j = sum_k kQuadraticFit[j][k] s_k and out = clip(b + ((q(x, y) + 2^23) >> 24)), q evaluated
// with the c_j in 64 bits.
// (With AVX2 evaluated by forward differences, exactly.)
void predict_quadratic16(const uint16_t* plane, int stride, int x0, int y0, int max_value,
                         int32_t* out);
// The same by evaluating q at every sample (the definition; tests check that both are equal).
void predict_quadratic16_reference(const uint16_t* plane, int stride, int x0, int y0, int max_value,
                                   int32_t* out);

}  // namespace gvkit::codec
