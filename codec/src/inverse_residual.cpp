// The 16x16 fast path: the inverse transform as two matrix products (columns, then rows) over
// the nonzero rows and columns of the level block, eight 32-bit lanes wide. Exactness: with S =
// the sum of |coefficient| over the block, every partial sum of the first pass is at most
// 90 S + 64 in magnitude (90 = the largest |matrix entry|), the first pass's outputs of a row
// sum to at most (90 S + 16 x 64) / 128 + 16, and every partial sum of the second pass is at
// most 90 x that + 4096 < 64 S + 2^13. S <= 2^24 keeps all of them below 2^31 (and the outputs
// far inside the reference's clamp of +-2^30), so 32-bit sums equal the reference's 64-bit
// ones; larger blocks take the reference.
#include "gvkit/codec/inverse_residual.hpp"

#include "gvkit/codec/transform.hpp"
#include "gvkit/codec/transform16x16.hpp"
#include "gvkit/core/cpu_features.hpp"

namespace gvkit::codec {
namespace {

void reference16x16(const int32_t* levels, int qp_prime, int32_t* residual) {
  int64_t coeffs[256];
  dequantize16x16(levels, qp_prime, coeffs);
  inverse_transform16x16(coeffs, residual);
}

#if defined(GVKIT_X86_SIMD)
constexpr int64_t kMaxCoefficientSum = int64_t{1} << 24;

// False (nothing written) when the block is outside the 32-bit bound.
GVKIT_TARGET_AVX2 bool inverse_residual16x16_avx2(const int32_t* levels, int qp_prime,
                                                  int32_t* residual) {
  const __m256i* in = reinterpret_cast<const __m256i*>(levels);
  // |level| as unsigned (abs of INT32_MIN reads as 2^31), its maximum, the nonzero rows and the
  // nonzero columns (lanes).
  __m256i max_abs = _mm256_setzero_si256(), cols_lo = max_abs, cols_hi = max_abs;
  __m256i abs_rows[16];
  unsigned rows = 0;
  for (int l = 0; l < 16; ++l) {
    const __m256i a = _mm256_loadu_si256(in + 2 * l), b = _mm256_loadu_si256(in + 2 * l + 1);
    cols_lo = _mm256_or_si256(cols_lo, a);
    cols_hi = _mm256_or_si256(cols_hi, b);
    const __m256i abs_a = _mm256_abs_epi32(a), abs_b = _mm256_abs_epi32(b);
    max_abs = _mm256_max_epu32(max_abs, _mm256_max_epu32(abs_a, abs_b));
    abs_rows[l] = _mm256_add_epi32(abs_a, abs_b);  // < 2^24 each once max_abs < 2^23
    if (!_mm256_testz_si256(_mm256_or_si256(a, b), _mm256_or_si256(a, b))) rows |= 1u << l;
  }
  alignas(32) uint32_t lanes[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), max_abs);
  uint32_t largest = 0;
  for (const uint32_t v : lanes) largest = v > largest ? v : largest;
  if (largest >= (1u << 23)) return false;
  __m256i sum = _mm256_setzero_si256();  // 256 x 2^23 < 2^31: no overflow
  for (int l = 0; l < 16; ++l) sum = _mm256_add_epi32(sum, abs_rows[l]);
  _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), sum);
  int64_t level_sum = 0;
  for (const uint32_t v : lanes) level_sum += v;
  const int64_t scale = dequantization_scale16x16(qp_prime);
  if (level_sum * scale > kMaxCoefficientSum) return false;
  // Nonzero columns: bit x of the masks.
  const __m256i zero = _mm256_setzero_si256();
  const unsigned cols =
      (~static_cast<unsigned>(
           _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(cols_lo, zero)))) &
       0xFFu) |
      ((~static_cast<unsigned>(
            _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(cols_hi, zero)))) &
        0xFFu)
       << 8);
  const bool high = (cols >> 8) != 0;  // any level in columns 8..15
  const __m256i s = _mm256_set1_epi32(static_cast<int32_t>(scale));
  // First pass: t[y] = round(sum over the nonzero rows l of M[l][y] c[l], 7), per column.
  alignas(32) int32_t t[256];
  const __m256i round1 = _mm256_set1_epi32(64), round2 = _mm256_set1_epi32(4096);
  __m256i c_lo[16], c_hi[16];
  int row_list[16], row_count = 0;
  for (int l = 0; l < 16; ++l)
    if ((rows >> l) & 1) {
      c_lo[row_count] = _mm256_mullo_epi32(_mm256_loadu_si256(in + 2 * l), s);
      c_hi[row_count] = _mm256_mullo_epi32(_mm256_loadu_si256(in + 2 * l + 1), s);
      row_list[row_count++] = l;
    }
  for (int y = 0; y < 16; ++y) {
    __m256i lo = zero, hi = zero;
    for (int i = 0; i < row_count; ++i) {
      const __m256i m = _mm256_set1_epi32(kTransform16[row_list[i]][y]);
      lo = _mm256_add_epi32(lo, _mm256_mullo_epi32(m, c_lo[i]));
      if (high) hi = _mm256_add_epi32(hi, _mm256_mullo_epi32(m, c_hi[i]));
    }
    _mm256_store_si256(reinterpret_cast<__m256i*>(t + 16 * y),
                       _mm256_srai_epi32(_mm256_add_epi32(lo, round1), 7));
    _mm256_store_si256(reinterpret_cast<__m256i*>(t + 16 * y + 8),
                       _mm256_srai_epi32(_mm256_add_epi32(hi, round1), 7));
  }
  // Second pass: r[y][x] = round(sum over the nonzero columns k of t[y][k] M[k][x], 13).
  __m256i m_lo[16], m_hi[16];
  int col_list[16], col_count = 0;
  for (int k = 0; k < 16; ++k)
    if ((cols >> k) & 1) {
      m_lo[col_count] = _mm256_cvtepi8_epi32(
          _mm_loadl_epi64(reinterpret_cast<const __m128i*>(&kTransform16[k][0])));
      m_hi[col_count] = _mm256_cvtepi8_epi32(
          _mm_loadl_epi64(reinterpret_cast<const __m128i*>(&kTransform16[k][8])));
      col_list[col_count++] = k;
    }
  __m256i* out = reinterpret_cast<__m256i*>(residual);
  for (int y = 0; y < 16; ++y) {
    __m256i lo = zero, hi = zero;
    for (int i = 0; i < col_count; ++i) {
      const __m256i v = _mm256_set1_epi32(t[16 * y + col_list[i]]);
      lo = _mm256_add_epi32(lo, _mm256_mullo_epi32(v, m_lo[i]));
      hi = _mm256_add_epi32(hi, _mm256_mullo_epi32(v, m_hi[i]));
    }
    _mm256_storeu_si256(out + 2 * y, _mm256_srai_epi32(_mm256_add_epi32(lo, round2), 13));
    _mm256_storeu_si256(out + 2 * y + 1, _mm256_srai_epi32(_mm256_add_epi32(hi, round2), 13));
  }
  return true;
}
#endif

}  // namespace

void inverse_residual_reference(int n, const int32_t* levels, int qp_prime, int32_t* residual) {
  if (n == 16) return reference16x16(levels, qp_prime, residual);
  int64_t coeffs[64];
  dequantize(n, levels, qp_prime, coeffs);
  if (n == 4)
    inverse_transform4x4(coeffs, residual);
  else
    inverse_transform8x8(coeffs, residual);
}

void inverse_residual(int n, const int32_t* levels, int qp_prime, int32_t* residual) {
#if defined(GVKIT_X86_SIMD)
  if (n == 16 && gvkit::detail::cpu_has_avx2() &&
      inverse_residual16x16_avx2(levels, qp_prime, residual))
    return;
#endif
  inverse_residual_reference(n, levels, qp_prime, residual);
}

}  // namespace gvkit::codec
