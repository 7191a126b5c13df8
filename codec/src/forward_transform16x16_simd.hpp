#pragma once
// forward_transform16x16 in 32-bit arithmetic, sixteen columns at a time (vectorised; AVX2 where
// the CPU has it), for residuals whose magnitudes stay within kForward16x16MaxInput32 (every
// intermediate sum then stays below 2^31: pass 1 sums at most 1024 |r|, pass 2 at most 1024 x
// (128 |r| + 1)). Output identical to forward_transform16x16's int64 butterfly and to
// forward_transform16x16_reference (tests/codec/transform_test.cpp checks them on random blocks).

#include <cstdint>

namespace gvkit::codec::detail {

inline constexpr int32_t kForward16x16MaxInput32 = 16000;

// Whether every |residual[i]| (256 values, raster order) is at most kForward16x16MaxInput32.
bool forward_transform16x16_fits_32(const int32_t* residual);
// The transform of a residual that fits (contract): the portable 32-bit version and the one that
// uses AVX2 when the CPU has it.
void forward_transform16x16_32(const int32_t* residual, int32_t* coeffs);
void forward_transform16x16_32_avx2(const int32_t* residual, int32_t* coeffs);

}  // namespace gvkit::codec::detail
