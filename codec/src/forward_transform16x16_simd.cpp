#include "forward_transform16x16_simd.hpp"

#include <cstdlib>

#include "gvkit/codec/transform16x16.hpp"
#include "gvkit/core/cpu_features.hpp"

namespace gvkit::codec::detail {
namespace {

// One forward pass along the first index, all sixteen columns at once:
// out[k][j] = round_shift(sum_n M[k][n] in[n][j], shift), with M = kTransform16 in its
// partial-butterfly form (forward_transform16x16's). Every sum stays below 2^31 in magnitude when
// |in| <= kMaxInput32 (pass 1) or its output (pass 2): see forward_transform16x16_fits_32.
template <int kShift>
[[gnu::always_inline]] inline void forward_pass(const int32_t (&in)[16][16],
                                                int32_t (&out)[16][16]) {
  constexpr int32_t kRound = 1 << (kShift - 1);
  const auto& m = kTransform16;
  int32_t e[8][16], o[8][16], ee[4][16], eo[4][16];
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 16; ++j) {
      e[k][j] = in[k][j] + in[15 - k][j];
      o[k][j] = in[k][j] - in[15 - k][j];
    }
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 16; ++j) {
      ee[k][j] = e[k][j] + e[7 - k][j];
      eo[k][j] = e[k][j] - e[7 - k][j];
    }
  for (int j = 0; j < 16; ++j) {
    const int32_t eee0 = ee[0][j] + ee[3][j], eeo0 = ee[0][j] - ee[3][j];
    const int32_t eee1 = ee[1][j] + ee[2][j], eeo1 = ee[1][j] - ee[2][j];
    out[0][j] = (64 * eee0 + 64 * eee1 + kRound) >> kShift;
    out[8][j] = (64 * eee0 - 64 * eee1 + kRound) >> kShift;
    out[4][j] = (83 * eeo0 + 36 * eeo1 + kRound) >> kShift;
    out[12][j] = (36 * eeo0 - 83 * eeo1 + kRound) >> kShift;
  }
  for (int k = 2; k < 16; k += 4)
    for (int j = 0; j < 16; ++j) {
      int32_t s = kRound;
      for (int n = 0; n < 4; ++n) s += m[k][n] * eo[n][j];
      out[k][j] = s >> kShift;
    }
  for (int k = 1; k < 16; k += 2)
    for (int j = 0; j < 16; ++j) {
      int32_t s = kRound;
      for (int n = 0; n < 8; ++n) s += m[k][n] * o[n][j];
      out[k][j] = s >> kShift;
    }
}

[[gnu::always_inline]] inline void transpose(const int32_t (&in)[16][16], int32_t (&out)[16][16]) {
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 16; ++j) out[j][i] = in[i][j];
}

// The two passes of forward_transform16x16: rows (over x) with shift 3, then columns (over y)
// with shift 5; the row pass runs on the transposed block so that both passes combine whole
// rows of sixteen values.
template <class = void>
[[gnu::always_inline]] inline void forward16_32(const int32_t* residual, int32_t* coeffs) {
  int32_t a[16][16], b[16][16];
  const auto& r = *reinterpret_cast<const int32_t(*)[16][16]>(residual);
  transpose(r, a);        // a[x][y]
  forward_pass<3>(a, b);  // b[k][y] = t[y][k]
  transpose(b, a);        // a[y][k] = t
  forward_pass<5>(a, b);  // b[l][k]
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 16; ++j) coeffs[i * 16 + j] = b[i][j];
}

#if defined(GVKIT_X86_SIMD)
GVKIT_TARGET_AVX2 void forward16_32_avx2(const int32_t* residual, int32_t* coeffs) {
  forward16_32(residual, coeffs);
}
#else
void forward16_32_avx2(const int32_t* residual, int32_t* coeffs) { forward16_32(residual, coeffs); }
#endif

}  // namespace

bool forward_transform16x16_fits_32(const int32_t* residual) {
  for (int i = 0; i < 256; ++i)
    if (std::abs(residual[i]) > kForward16x16MaxInput32) return false;
  return true;
}

void forward_transform16x16_32(const int32_t* residual, int32_t* coeffs) {
  forward16_32(residual, coeffs);
}

void forward_transform16x16_32_avx2(const int32_t* residual, int32_t* coeffs) {
  if (gvkit::detail::cpu_has_avx2())
    forward16_32_avx2(residual, coeffs);
  else
    forward16_32(residual, coeffs);
}

}  // namespace gvkit::codec::detail
