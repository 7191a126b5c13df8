// The 16x16 fast path: the inverse transform as two matrix products (columns, then rows) over
// the nonzero rows and columns of the level block, eight 32-bit lanes wide. Exactness: with S =
// the sum of |coefficient| over the block, every partial sum of the first pass is at most
// 90 S + 64 in magnitude (90 = the largest |matrix entry|), the first pass's outputs of a row
// sum to at most (90 S + 16 x 64) / 128 + 16, and every partial sum of the second pass is at
// most 90 x that + 4096 < 64 S + 2^13. S <= 2^24 keeps all of them below 2^31 (and the outputs
// far inside the reference's clamp of +-2^30), so 32-bit sums equal the reference's 64-bit
// ones; larger blocks take the reference.
//
// The 8x8 fast path: dequantization and both passes of the butterfly in 32-bit lanes, one row or
// column of the block per vector (two 8x8 transposes between them), rows first as the
// reference. Exactness: with L = sum |level| x 2^(qp'/6), every coefficient is at most
// |level| x 16 x 58 x 2^(qp'/6) / 64 + 1 (58 = the largest factor), so their sum S <= 15 L + 64.
// Every value of a one-dimensional butterfly is at most 3 x (the sum of its |inputs|) + 4, so the
// first pass's are at most 3 S + 4, a column's inputs to the second pass sum to at most 3 S + 32,
// and the second pass's values (+ 32) stay below 9 S + 132. 15 L + 64 <= 2^24 keeps every one,
// and the products of the dequantization (at most 928 L), below 2^31: 32-bit sums and arithmetic
// shifts equal the reference's 64-bit ones; larger blocks take the reference.
//
// The 4x4 fast path, alike with four lanes: coefficients are at most 29 |level| 2^(qp'/6) (29 =
// the largest factor), a butterfly's values at most 1.5 x the sum of its |inputs| + 1, so the
// second pass's values (+ 32) stay below 2.25 S + 40 with S <= 29 L; 29 L <= 2^24 keeps them and
// the products of the dequantization below 2^31.
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

// inverse_residual16x16_avx2 with sixteen lanes: a row of the block per vector, so each product
// of a pass is one instruction instead of two. The same bound, sums and shifts. (GCC 12's
// avx512fintrin.h fills unused operands with a self-initialised _mm512_undefined_epi32, which
// its own -Wuninitialized reports.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
GVKIT_TARGET_AVX512 bool inverse_residual16x16_avx512(const int32_t* levels, int qp_prime,
                                                      int32_t* residual) {
  // |level| as unsigned (abs of INT32_MIN reads as 2^31), its maximum, the nonzero rows and the
  // nonzero columns (lanes).
  __m512i max_abs = _mm512_setzero_si512(), cols_any = max_abs, abs_sum = max_abs;
  __m512i row[16];
  unsigned rows = 0;
  for (int l = 0; l < 16; ++l) {
    row[l] = _mm512_loadu_si512(levels + 16 * l);
    cols_any = _mm512_or_si512(cols_any, row[l]);
    const __m512i a = _mm512_abs_epi32(row[l]);
    max_abs = _mm512_max_epu32(max_abs, a);
    abs_sum = _mm512_add_epi32(abs_sum, a);  // 16 x 2^23 per lane once max_abs < 2^23
    if (_mm512_test_epi32_mask(row[l], row[l])) rows |= 1u << l;
  }
  if (_mm512_reduce_max_epu32(max_abs) >= (1u << 23)) return false;
  // 256 x 2^23 = 2^31: the lanes' total fits an unsigned 32-bit sum.
  const int64_t level_sum = static_cast<uint32_t>(_mm512_reduce_add_epi32(abs_sum));
  const int64_t scale = dequantization_scale16x16(qp_prime);
  if (level_sum * scale > kMaxCoefficientSum) return false;
  const unsigned cols = _mm512_test_epi32_mask(cols_any, cols_any);
  const __m512i s = _mm512_set1_epi32(static_cast<int32_t>(scale));
  // First pass: t[y] = round(sum over the nonzero rows l of M[l][y] c[l], 7), per column.
  alignas(64) int32_t t[256];
  const __m512i round1 = _mm512_set1_epi32(64), round2 = _mm512_set1_epi32(4096);
  __m512i c[16];
  int row_list[16], row_count = 0;
  for (int l = 0; l < 16; ++l)
    if ((rows >> l) & 1) {
      c[row_count] = _mm512_mullo_epi32(row[l], s);
      row_list[row_count++] = l;
    }
  for (int y = 0; y < 16; ++y) {
    __m512i sum = _mm512_setzero_si512();
    for (int i = 0; i < row_count; ++i)
      sum = _mm512_add_epi32(
          sum, _mm512_mullo_epi32(_mm512_set1_epi32(kTransform16[row_list[i]][y]), c[i]));
    _mm512_store_si512(t + 16 * y, _mm512_srai_epi32(_mm512_add_epi32(sum, round1), 7));
  }
  // Second pass: r[y][x] = round(sum over the nonzero columns k of t[y][k] M[k][x], 13).
  __m512i m[16];
  int col_list[16], col_count = 0;
  for (int k = 0; k < 16; ++k)
    if ((cols >> k) & 1) {
      m[col_count] = _mm512_cvtepi8_epi32(
          _mm_loadu_si128(reinterpret_cast<const __m128i*>(&kTransform16[k][0])));
      col_list[col_count++] = k;
    }
  for (int y = 0; y < 16; ++y) {
    __m512i sum = _mm512_setzero_si512();
    for (int i = 0; i < col_count; ++i)
      sum = _mm512_add_epi32(sum,
                             _mm512_mullo_epi32(_mm512_set1_epi32(t[16 * y + col_list[i]]), m[i]));
    _mm512_storeu_si512(residual + 16 * y, _mm512_srai_epi32(_mm512_add_epi32(sum, round2), 13));
  }
  return true;
}
#pragma GCC diagnostic pop

GVKIT_TARGET_AVX2 inline void transpose8x8(__m256i* r) {
  const __m256i t0 = _mm256_unpacklo_epi32(r[0], r[1]), t1 = _mm256_unpackhi_epi32(r[0], r[1]);
  const __m256i t2 = _mm256_unpacklo_epi32(r[2], r[3]), t3 = _mm256_unpackhi_epi32(r[2], r[3]);
  const __m256i t4 = _mm256_unpacklo_epi32(r[4], r[5]), t5 = _mm256_unpackhi_epi32(r[4], r[5]);
  const __m256i t6 = _mm256_unpacklo_epi32(r[6], r[7]), t7 = _mm256_unpackhi_epi32(r[6], r[7]);
  const __m256i u0 = _mm256_unpacklo_epi64(t0, t2), u1 = _mm256_unpackhi_epi64(t0, t2);
  const __m256i u2 = _mm256_unpacklo_epi64(t1, t3), u3 = _mm256_unpackhi_epi64(t1, t3);
  const __m256i u4 = _mm256_unpacklo_epi64(t4, t6), u5 = _mm256_unpackhi_epi64(t4, t6);
  const __m256i u6 = _mm256_unpacklo_epi64(t5, t7), u7 = _mm256_unpackhi_epi64(t5, t7);
  r[0] = _mm256_permute2x128_si256(u0, u4, 0x20);
  r[1] = _mm256_permute2x128_si256(u1, u5, 0x20);
  r[2] = _mm256_permute2x128_si256(u2, u6, 0x20);
  r[3] = _mm256_permute2x128_si256(u3, u7, 0x20);
  r[4] = _mm256_permute2x128_si256(u0, u4, 0x31);
  r[5] = _mm256_permute2x128_si256(u1, u5, 0x31);
  r[6] = _mm256_permute2x128_si256(u2, u6, 0x31);
  r[7] = _mm256_permute2x128_si256(u3, u7, 0x31);
}

GVKIT_TARGET_AVX2 inline __m256i add(__m256i a, __m256i b) { return _mm256_add_epi32(a, b); }
GVKIT_TARGET_AVX2 inline __m256i sub(__m256i a, __m256i b) { return _mm256_sub_epi32(a, b); }
GVKIT_TARGET_AVX2 inline __m256i half(__m256i a) { return _mm256_srai_epi32(a, 1); }
GVKIT_TARGET_AVX2 inline __m256i quarter(__m256i a) { return _mm256_srai_epi32(a, 2); }

// transform.cpp's idct8_1d on eight lanes at once, d[k] holding input and output k.
GVKIT_TARGET_AVX2 inline void idct8_lanes(__m256i* d) {
  const __m256i a0 = add(d[0], d[4]), a4 = sub(d[0], d[4]);
  const __m256i a2 = sub(half(d[2]), d[6]), a6 = add(d[2], half(d[6]));
  const __m256i b0 = add(a0, a6), b2 = add(a4, a2), b4 = sub(a4, a2), b6 = sub(a0, a6);
  const __m256i a1 = sub(sub(sub(d[5], d[3]), d[7]), half(d[7]));
  const __m256i a3 = sub(sub(add(d[1], d[7]), d[3]), half(d[3]));
  const __m256i a5 = add(add(sub(d[7], d[1]), d[5]), half(d[5]));
  const __m256i a7 = add(add(add(d[3], d[5]), d[1]), half(d[1]));
  const __m256i b1 = add(a1, quarter(a7)), b7 = sub(a7, quarter(a1));
  const __m256i b3 = add(a3, quarter(a5)), b5 = sub(quarter(a3), a5);
  d[0] = add(b0, b7);
  d[1] = add(b2, b5);
  d[2] = add(b4, b3);
  d[3] = add(b6, b1);
  d[4] = sub(b6, b1);
  d[5] = sub(b4, b3);
  d[6] = sub(b2, b5);
  d[7] = sub(b0, b7);
}

// transform.cpp's inverse_transform4x4 butterfly on four lanes, d[k] holding input and output k.
GVKIT_TARGET_AVX2 inline void idct4_lanes(__m128i* d) {
  const __m128i e = _mm_add_epi32(d[0], d[2]), f = _mm_sub_epi32(d[0], d[2]);
  const __m128i g = _mm_sub_epi32(_mm_srai_epi32(d[1], 1), d[3]);
  const __m128i h = _mm_add_epi32(d[1], _mm_srai_epi32(d[3], 1));
  d[0] = _mm_add_epi32(e, h);
  d[1] = _mm_add_epi32(f, g);
  d[2] = _mm_sub_epi32(f, g);
  d[3] = _mm_sub_epi32(e, h);
}

GVKIT_TARGET_AVX2 inline void transpose4x4(__m128i* r) {
  const __m128i t0 = _mm_unpacklo_epi32(r[0], r[1]), t1 = _mm_unpackhi_epi32(r[0], r[1]);
  const __m128i t2 = _mm_unpacklo_epi32(r[2], r[3]), t3 = _mm_unpackhi_epi32(r[2], r[3]);
  r[0] = _mm_unpacklo_epi64(t0, t2);
  r[1] = _mm_unpackhi_epi64(t0, t2);
  r[2] = _mm_unpacklo_epi64(t1, t3);
  r[3] = _mm_unpackhi_epi64(t1, t3);
}

// The sum of |levels[k]| over count levels (a multiple of 8), or -1 when one is 2^23 or more
// (INT32_MIN included): the first test of the 4x4 and 8x8 paths' bound.
GVKIT_TARGET_AVX2 int64_t level_magnitude_sum(const int32_t* levels, int count) {
  __m256i max_abs = _mm256_setzero_si256(), abs_sum = max_abs;
  for (int k = 0; k < count; k += 8) {
    // INT32_MIN reads as 2^31 (unsigned); 64 x 2^23 < 2^31 once max_abs < 2^23.
    const __m256i a =
        _mm256_abs_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(levels + k)));
    max_abs = _mm256_max_epu32(max_abs, a);
    abs_sum = _mm256_add_epi32(abs_sum, a);
  }
  alignas(32) uint32_t lanes[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), max_abs);
  uint32_t largest = 0;
  for (const uint32_t v : lanes) largest = v > largest ? v : largest;
  if (largest >= (1u << 23)) return -1;
  _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), abs_sum);
  int64_t sum = 0;
  for (const uint32_t v : lanes) sum += v;
  return sum;
}

// False (nothing written) when the block is outside the 32-bit bound.
GVKIT_TARGET_AVX2 bool inverse_residual4x4_avx2(const int32_t* levels, int qp_prime,
                                                int32_t* residual) {
  const int64_t level_sum = level_magnitude_sum(levels, 16);
  const int per = qp_prime / 6;
  if (level_sum < 0 || 29 * (level_sum << per) > kMaxCoefficientSum) return false;
  const __m128i* in = reinterpret_cast<const __m128i*>(levels);
  __m128i row[4];
  for (int i = 0; i < 4; ++i) row[i] = _mm_loadu_si128(in + i);
  const __m128i* factor = reinterpret_cast<const __m128i*>(dequantization_factors4x4(qp_prime));
  const __m128i shift = _mm_cvtsi32_si128(per);
  for (int i = 0; i < 4; ++i)
    row[i] = _mm_sll_epi32(_mm_mullo_epi32(row[i], _mm_loadu_si128(factor + i)), shift);
  transpose4x4(row);  // row[k]: column k
  idct4_lanes(row);   // each block row's transform, lane i = row i
  transpose4x4(row);  // row[k]: row k
  idct4_lanes(row);   // each column's transform
  const __m128i round = _mm_set1_epi32(32);
  __m128i* out = reinterpret_cast<__m128i*>(residual);
  for (int i = 0; i < 4; ++i)
    _mm_storeu_si128(out + i, _mm_srai_epi32(_mm_add_epi32(row[i], round), 6));
  return true;
}

// False (nothing written) when the block is outside the 32-bit bound.
GVKIT_TARGET_AVX2 bool inverse_residual8x8_avx2(const int32_t* levels, int qp_prime,
                                                int32_t* residual) {
  const int64_t level_sum = level_magnitude_sum(levels, 64);
  const int per = qp_prime / 6;
  if (level_sum < 0 || 15 * (level_sum << per) + 64 > kMaxCoefficientSum) return false;
  const __m256i* in = reinterpret_cast<const __m256i*>(levels);
  __m256i row[8];
  for (int i = 0; i < 8; ++i) row[i] = _mm256_loadu_si256(in + i);
  // Dequantization: (level x factor) << (4 + per), + 32, >> 6.
  const __m256i* factor = reinterpret_cast<const __m256i*>(dequantization_factors8x8(qp_prime));
  const __m128i shift = _mm_cvtsi32_si128(4 + per);
  const __m256i round = _mm256_set1_epi32(32);
  for (int i = 0; i < 8; ++i) {
    const __m256i scaled =
        _mm256_sll_epi32(_mm256_mullo_epi32(row[i], _mm256_loadu_si256(factor + i)), shift);
    row[i] = _mm256_srai_epi32(_mm256_add_epi32(scaled, round), 6);
  }
  transpose8x8(row);  // row[k]: column k
  idct8_lanes(row);   // each block row's transform, lane i = row i
  transpose8x8(row);  // row[k]: row k
  idct8_lanes(row);   // each column's transform
  __m256i* out = reinterpret_cast<__m256i*>(residual);
  for (int i = 0; i < 8; ++i)
    _mm256_storeu_si256(out + i, _mm256_srai_epi32(_mm256_add_epi32(row[i], round), 6));
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
  if (n == 16 && gvkit::detail::cpu_has_avx512() &&
      inverse_residual16x16_avx512(levels, qp_prime, residual))
    return;
  if (n == 16 && gvkit::detail::cpu_has_avx2() &&
      inverse_residual16x16_avx2(levels, qp_prime, residual))
    return;
  if (n == 8 && gvkit::detail::cpu_has_avx2() &&
      inverse_residual8x8_avx2(levels, qp_prime, residual))
    return;
  if (n == 4 && gvkit::detail::cpu_has_avx2() &&
      inverse_residual4x4_avx2(levels, qp_prime, residual))
    return;
#endif
  inverse_residual_reference(n, levels, qp_prime, residual);
}

}  // namespace gvkit::codec
