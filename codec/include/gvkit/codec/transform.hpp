#pragma once
// H.264 integer transforms (4x4 and 8x8, clauses 8.5.12 and 8.5.13), scalar quantization with
// QP' = QP + 6 (B - 8) for B-bit samples, zig-zag scans, and the 4x4 Hadamard SATD used by the
// fast mode decision. Blocks are row-major arrays of n*n values.

#include <cstdint>

namespace gvkit::codec {

// Forward core transforms of a residual block (|residual| < 2^17).
void forward_transform4x4(const int32_t* residual, int32_t* coeffs);
void forward_transform8x8(const int32_t* residual, int32_t* coeffs);
// Inverse transforms of dequantized coefficients, including the final (x + 32) >> 6.
void inverse_transform4x4(const int64_t* coeffs, int32_t* residual);
void inverse_transform8x8(const int64_t* coeffs, int32_t* residual);

// qp_prime = QP + 6 (B - 8), 0 <= qp_prime <= 99. Intra dead zone (rounding offset 1/3).
void quantize(int n, const int32_t* coeffs, int qp_prime, int32_t* levels);
// As quantize, with the rounding offset 1/6 of a step instead of 1/3 (H.264's reference encoder
// for inter blocks): a wider dead zone, fewer isolated small levels.
void quantize_inter(int n, const int32_t* coeffs, int qp_prime, int32_t* levels);
void dequantize(int n, const int32_t* levels, int qp_prime, int64_t* coeffs);
// The 64 per-position factors of dequantize(8, ...) at qp_prime % 6 (raster order, 18..58): a
// coefficient is (level x factor x 16 x 2^(qp_prime / 6) + 32) >> 6.
const int32_t* dequantization_factors8x8(int qp_prime);
// The 16 per-position factors of dequantize(4, ...) at qp_prime % 6 (raster order, 10..29): a
// coefficient is level x factor x 2^(qp_prime / 6).
const int32_t* dequantization_factors4x4(int qp_prime);
// The numerators of quantize (n = 4 or 8): numer[k] = |coeffs[k]| x the quantizer multiplier of
// position k; returns qbits. quantize's level is (numer + offset) >> qbits, and
// numer / 2^qbits is the unrounded magnitude in quantizer steps (rate-distortion optimised
// quantization, rdo_quantization.hpp).
int quantization_numerators(int n, const int32_t* coeffs, int qp_prime, int64_t* numer);
// out[k] = |values[k]| x factors[k] (0 <= factors[k] < 2^31) as 64-bit products, k < count,
// four at a time where SSE2 is (the numerators of quantization); the same with one factor.
void absolute_products(const int32_t* values, const int32_t* factors, int count, int64_t* out);
void absolute_products(const int32_t* values, int32_t factor, int count, int64_t* out);
// The plain per-position formulas of the same (kept to check the table-driven versions).
void quantize_reference(int n, const int32_t* coeffs, int qp_prime, int32_t* levels);
void dequantize_reference(int n, const int32_t* levels, int qp_prime, int64_t* coeffs);
// Quantizer step size (in sample units of the coded bit depth) of qp_prime: 0.625 * 2^(qp'/6).
double quantizer_step(int qp_prime);

// Scan position -> raster index of the zig-zag scans.
extern const uint8_t kZigzag4x4[16];
extern const uint8_t kZigzag8x8[64];

// Sum of absolute 4x4 Hadamard-transformed differences, halved (x264's convention).
int64_t satd4x4(const int32_t* diff, int stride);

}  // namespace gvkit::codec
