#pragma once
// The spatial residual of a lossy block's levels: dequantization followed by the inverse
// transform of its size (n = 4, 8: transform.hpp; n = 16: transform16x16.hpp), as the decoder
// and the encoder's reconstruction both add it to a prediction. Blocks are row-major n x n.
//
// inverse_residual returns the values of inverse_residual_reference bit for bit for any levels
// and qp_prime (0..99). Decoded blocks are mostly sparse and small: every size then works in 32
// bits with AVX2 (where the processor has it): the 16x16 path over the rows and columns that
// hold levels only (with AVX-512 a whole row per vector), the 8x8 and 4x4 paths as butterflies
// on a row or column per vector; each falls back to the 64-bit transform when the levels are too
// large for 32 bits to be exact.

#include <cstdint>

namespace gvkit::codec {

void inverse_residual(int n, const int32_t* levels, int qp_prime, int32_t* residual);
// dequantize + inverse_transform4x4 / inverse_transform8x8, or dequantize16x16 +
// inverse_transform16x16.
void inverse_residual_reference(int n, const int32_t* levels, int qp_prime, int32_t* residual);

}  // namespace gvkit::codec
