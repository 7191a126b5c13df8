#pragma once
// The 16x16 integer transform of the larger-transforms tool (format 1.6, docs/bitstream.md 4.8):
// HEVC's 16-point core transform matrix (ITU-T H.265 8.6.4.2; entries 64, 90, 89, ..., 9, rows
// of norm ~256, i.e. 256 x an orthonormal DCT-II), its quantization with the quantizer step of
// the 4x4 / 8x8 paths (quantizer_step(qp')), and the 16x16 zig-zag scan. Blocks are row-major
// arrays of 256 values.
//
// Scaling: forward_transform16x16 returns 2^8 x the orthonormal 2D DCT of the residual (shifts
// 3 and 5 after the two passes, rounded); |residual| < 2^17 keeps every value below 2^30.
// dequantize16x16 returns 16 x the reconstructed orthonormal coefficient (level x step x 16,
// exact), and inverse_transform16x16 maps that back to samples (shifts 7 and 13, rounded). All
// intermediate sums are 64-bit: any levels a decoder may read (|level| < 2^24, qp' <= 99) stay
// below 2^59; the output is clamped to +-2^30.

#include <array>
#include <cstdint>

namespace gvkit::codec {

// The 16-point core transform matrix: kTransform16[k][n], row k = frequency.
extern const int8_t kTransform16[16][16];
// Scan position -> raster index of the 16x16 zig-zag scan (H.264's zig-zag pattern extended).
extern const std::array<uint16_t, 256> kZigzag16x16;

// Partial-butterfly forward / inverse transforms (the reference versions below give the same
// values, bit for bit). The forward transform takes 32-bit vectorised arithmetic where every
// |residual| <= 16000 (nearly always), else forward_transform16x16_butterfly64.
void forward_transform16x16(const int32_t* residual, int32_t* coeffs);
void forward_transform16x16_butterfly64(const int32_t* residual, int32_t* coeffs);
void inverse_transform16x16(const int64_t* coeffs, int32_t* residual);
// forward_transform4x4, forward_transform8x8 or forward_transform16x16 by n (4, 8 or 16).
void forward_transform(int n, const int32_t* residual, int32_t* coeffs);
// Plain matrix products with the same shifts and rounding.
void forward_transform16x16_reference(const int32_t* residual, int32_t* coeffs);
void inverse_transform16x16_reference(const int64_t* coeffs, int32_t* residual);

// Quantization of forward_transform16x16's output at qp' (0..99): level = the coefficient over
// the step quantizer_step(qp'), rounded with the offset 1/3 of a step (intra) or 1/6 (inter,
// the wider dead zone of quantize_inter).
void quantize16x16(const int32_t* coeffs, int qp_prime, bool inter_dead_zone, int32_t* levels);
// The numerators of quantize16x16: numer[k] = |coeffs[k]| x the quantizer multiplier; returns
// qbits (numer / 2^qbits is the unrounded magnitude in quantizer steps).
int quantization_numerators16x16(const int32_t* coeffs, int qp_prime, int64_t* numer);
void dequantize16x16(const int32_t* levels, int qp_prime, int64_t* coeffs);
// dequantize16x16's factor: coeffs[k] = levels[k] x dequantization_scale16x16(qp_prime).
int64_t dequantization_scale16x16(int qp_prime);

}  // namespace gvkit::codec
