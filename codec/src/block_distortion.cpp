// SSE2 kernels (the x86-64 baseline) with the plain loops as the fallback elsewhere. SATD
// transforms each 4x4 block vertically first, transposes and transforms again: the sixteen
// Hadamard coefficients are the same as satd4x4's (row transform first), only their order differs,
// and all arithmetic is exact in 32 bits (|coefficient| < 2^21).
#include "gvkit/codec/block_distortion.hpp"

#include <cstdlib>

#include "gvkit/codec/transform.hpp"
#include "gvkit/core/cpu_features.hpp"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace gvkit::codec {

int64_t sad16x16_reference(const uint16_t* a, ptrdiff_t a_stride, const uint16_t* b,
                           ptrdiff_t b_stride) {
  int64_t sum = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      sum += std::abs(static_cast<int>(a[y * a_stride + x]) - b[y * b_stride + x]);
  return sum;
}

int64_t satd_block_of_average_reference(int n, const uint16_t* src, ptrdiff_t src_stride,
                                        const uint16_t* first, const uint16_t* second,
                                        ptrdiff_t pred_stride) {
  int32_t pred[256];
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const int32_t a = first[y * pred_stride + x];
      pred[y * n + x] = second ? (a + second[y * pred_stride + x] + 1) >> 1 : a;
    }
  return satd_block(n, src, src_stride, pred);
}

int64_t satd_block_reference(int n, const uint16_t* src, ptrdiff_t src_stride,
                             const int32_t* pred) {
  int32_t diff[256];
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      diff[y * n + x] = static_cast<int32_t>(src[y * src_stride + x]) - pred[y * n + x];
  int64_t sum = 0;
  for (int by = 0; by < n; by += 4)
    for (int bx = 0; bx < n; bx += 4) sum += satd4x4(diff + by * n + bx, n);
  return sum;
}

int64_t sad_block_reference(int n, const uint16_t* src, ptrdiff_t src_stride, const int32_t* pred) {
  int64_t sum = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      sum += std::abs(static_cast<int32_t>(src[y * src_stride + x]) - pred[y * n + x]);
  return sum;
}

void distortions4x4_of_reference(bool sad, const int32_t* source, const int32_t (*preds)[16],
                                 int count, int64_t* out) {
  for (int i = 0; i < count; ++i) {
    int32_t diff[16];
    int64_t sum = 0;
    for (int k = 0; k < 16; ++k) {
      diff[k] = source[k] - preds[i][k];
      sum += std::abs(diff[k]);
    }
    out[i] = sad ? sum : satd4x4(diff, 4);
  }
}

#if defined(__SSE2__)
namespace {

inline __m128i abs_epi32(__m128i v) {
  const __m128i s = _mm_srai_epi32(v, 31);
  return _mm_sub_epi32(_mm_xor_si128(v, s), s);
}

// Four uint16 samples widened to int32, minus four int32 predictions.
inline __m128i diff4(const uint16_t* src, const int32_t* pred) {
  const __m128i s = _mm_unpacklo_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(src)),
                                       _mm_setzero_si128());
  return _mm_sub_epi32(s, _mm_loadu_si128(reinterpret_cast<const __m128i*>(pred)));
}

inline void hadamard4(__m128i& a, __m128i& b, __m128i& c, __m128i& d) {
  const __m128i a0 = _mm_add_epi32(a, b), a1 = _mm_sub_epi32(a, b);
  const __m128i a2 = _mm_add_epi32(c, d), a3 = _mm_sub_epi32(c, d);
  a = _mm_add_epi32(a0, a2);
  b = _mm_add_epi32(a1, a3);
  c = _mm_sub_epi32(a0, a2);
  d = _mm_sub_epi32(a1, a3);
}

inline int32_t horizontal_sum(__m128i v) {
  v = _mm_add_epi32(v, _mm_shuffle_epi32(v, _MM_SHUFFLE(1, 0, 3, 2)));
  v = _mm_add_epi32(v, _mm_shuffle_epi32(v, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtsi128_si32(v);
}

// satd4x4 of the 4x4 block whose rows are r0..r3 (int32 differences).
inline int32_t satd4x4_rows(__m128i r0, __m128i r1, __m128i r2, __m128i r3) {
  hadamard4(r0, r1, r2, r3);
  const __m128i t0 = _mm_unpacklo_epi32(r0, r1), t1 = _mm_unpacklo_epi32(r2, r3);
  const __m128i t2 = _mm_unpackhi_epi32(r0, r1), t3 = _mm_unpackhi_epi32(r2, r3);
  r0 = _mm_unpacklo_epi64(t0, t1);
  r1 = _mm_unpackhi_epi64(t0, t1);
  r2 = _mm_unpacklo_epi64(t2, t3);
  r3 = _mm_unpackhi_epi64(t2, t3);
  hadamard4(r0, r1, r2, r3);
  const __m128i s = _mm_add_epi32(_mm_add_epi32(abs_epi32(r0), abs_epi32(r1)),
                                  _mm_add_epi32(abs_epi32(r2), abs_epi32(r3)));
  return horizontal_sum(s) / 2;
}

}  // namespace

int64_t sad16x16(const uint16_t* a, ptrdiff_t a_stride, const uint16_t* b, ptrdiff_t b_stride) {
  const __m128i zero = _mm_setzero_si128();
  __m128i acc = zero;
  for (int y = 0; y < 16; ++y, a += a_stride, b += b_stride)
    for (int x = 0; x < 16; x += 8) {
      const __m128i va = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + x));
      const __m128i vb = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + x));
      const __m128i d = _mm_or_si128(_mm_subs_epu16(va, vb), _mm_subs_epu16(vb, va));
      acc = _mm_add_epi32(acc,
                          _mm_add_epi32(_mm_unpacklo_epi16(d, zero), _mm_unpackhi_epi16(d, zero)));
    }
  // At most 256 * 65535 < 2^24: no overflow in 32-bit lanes.
  return horizontal_sum(acc);
}

namespace {

int64_t satd_block_sse2(int n, const uint16_t* src, ptrdiff_t src_stride, const int32_t* pred) {
  int64_t sum = 0;
  for (int by = 0; by < n; by += 4) {
    const uint16_t* s = src + by * src_stride;
    const int32_t* p = pred + by * n;
    for (int bx = 0; bx < n; bx += 4)
      sum += satd4x4_rows(diff4(s + bx, p + bx), diff4(s + src_stride + bx, p + n + bx),
                          diff4(s + 2 * src_stride + bx, p + 2 * n + bx),
                          diff4(s + 3 * src_stride + bx, p + 3 * n + bx));
  }
  return sum;
}

// The source block's rows as 32-bit lanes: from 16-bit samples, or given as 32-bit values.
void source_rows(const uint16_t* src, ptrdiff_t src_stride, __m128i (&s)[4]) {
  for (int r = 0; r < 4; ++r)
    s[r] =
        _mm_unpacklo_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(src + r * src_stride)),
                           _mm_setzero_si128());
}
void source_rows(const int32_t* source, __m128i (&s)[4]) {
  for (int r = 0; r < 4; ++r) s[r] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(source) + r);
}

void distortions4x4_sse2(bool sad, const __m128i (&s)[4], const int32_t (*preds)[16], int count,
                         int64_t* out) {
  for (int i = 0; i < count; ++i) {
    const __m128i* p = reinterpret_cast<const __m128i*>(preds[i]);
    const __m128i d0 = _mm_sub_epi32(s[0], _mm_loadu_si128(p)),
                  d1 = _mm_sub_epi32(s[1], _mm_loadu_si128(p + 1)),
                  d2 = _mm_sub_epi32(s[2], _mm_loadu_si128(p + 2)),
                  d3 = _mm_sub_epi32(s[3], _mm_loadu_si128(p + 3));
    out[i] = sad ? horizontal_sum(_mm_add_epi32(_mm_add_epi32(abs_epi32(d0), abs_epi32(d1)),
                                                _mm_add_epi32(abs_epi32(d2), abs_epi32(d3))))
                 : satd4x4_rows(d0, d1, d2, d3);
  }
}

#if defined(GVKIT_X86_SIMD)
// AVX2: two 4x4 blocks side by side, one per 128-bit lane (the unpacks work within lanes). The
// sixteen coefficients of a block all have the parity of its sum of differences, so each block's
// sum of magnitudes is even and halving the total equals halving each block.
GVKIT_TARGET_AVX2 inline void hadamard4_avx2(__m256i& a, __m256i& b, __m256i& c, __m256i& d) {
  const __m256i a0 = _mm256_add_epi32(a, b), a1 = _mm256_sub_epi32(a, b);
  const __m256i a2 = _mm256_add_epi32(c, d), a3 = _mm256_sub_epi32(c, d);
  a = _mm256_add_epi32(a0, a2);
  b = _mm256_add_epi32(a1, a3);
  c = _mm256_sub_epi32(a0, a2);
  d = _mm256_sub_epi32(a1, a3);
}

// Sum of |coefficients| of the two blocks whose rows are r0..r3, per lane (4 partial sums each).
GVKIT_TARGET_AVX2 inline __m256i satd_pair(__m256i r0, __m256i r1, __m256i r2, __m256i r3) {
  hadamard4_avx2(r0, r1, r2, r3);
  const __m256i t0 = _mm256_unpacklo_epi32(r0, r1), t1 = _mm256_unpacklo_epi32(r2, r3);
  const __m256i t2 = _mm256_unpackhi_epi32(r0, r1), t3 = _mm256_unpackhi_epi32(r2, r3);
  r0 = _mm256_unpacklo_epi64(t0, t1);
  r1 = _mm256_unpackhi_epi64(t0, t1);
  r2 = _mm256_unpacklo_epi64(t2, t3);
  r3 = _mm256_unpackhi_epi64(t2, t3);
  hadamard4_avx2(r0, r1, r2, r3);
  return _mm256_add_epi32(_mm256_add_epi32(_mm256_abs_epi32(r0), _mm256_abs_epi32(r1)),
                          _mm256_add_epi32(_mm256_abs_epi32(r2), _mm256_abs_epi32(r3)));
}

GVKIT_TARGET_AVX2 inline __m256i diff8(const uint16_t* src, const int32_t* pred) {
  return _mm256_sub_epi32(
      _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(src))),
      _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pred)));
}

GVKIT_TARGET_AVX2 inline int32_t lane_sum(__m128i v) { return horizontal_sum(v); }

GVKIT_TARGET_AVX2 int64_t satd_block_avx2(int n, const uint16_t* src, ptrdiff_t src_stride,
                                          const int32_t* pred) {
  if (n == 4) return satd_block_sse2(n, src, src_stride, pred);
  // Per lane at most 8 blocks x 16 coefficients < 2^21 each: < 2^28, no overflow.
  __m256i acc = _mm256_setzero_si256();
  for (int by = 0; by < n; by += 4) {
    const uint16_t* s = src + by * src_stride;
    const int32_t* p = pred + by * n;
    for (int bx = 0; bx < n; bx += 8)
      acc = _mm256_add_epi32(
          acc, satd_pair(diff8(s + bx, p + bx), diff8(s + src_stride + bx, p + n + bx),
                         diff8(s + 2 * src_stride + bx, p + 2 * n + bx),
                         diff8(s + 3 * src_stride + bx, p + 3 * n + bx)));
  }
  const __m128i v = _mm_add_epi32(_mm256_castsi256_si128(acc), _mm256_extracti128_si256(acc, 1));
  return lane_sum(v) / 2;
}

// src - the prediction's 8 samples at first (and second: their rounded average, pavgw).
GVKIT_TARGET_AVX2 inline __m256i diff8_of_average(const uint16_t* src, const uint16_t* first,
                                                  const uint16_t* second) {
  __m128i p = _mm_loadu_si128(reinterpret_cast<const __m128i*>(first));
  if (second) p = _mm_avg_epu16(p, _mm_loadu_si128(reinterpret_cast<const __m128i*>(second)));
  return _mm256_sub_epi32(
      _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(src))),
      _mm256_cvtepu16_epi32(p));
}

GVKIT_TARGET_AVX2 int64_t satd_block_of_average_avx2(int n, const uint16_t* src,
                                                     ptrdiff_t src_stride, const uint16_t* first,
                                                     const uint16_t* second,
                                                     ptrdiff_t pred_stride) {
  // As satd_block_avx2: per lane < 2^28.
  __m256i acc = _mm256_setzero_si256();
  for (int by = 0; by < n; by += 4)
    for (int bx = 0; bx < n; bx += 8) {
      __m256i d[4];
      for (int r = 0; r < 4; ++r) {
        const ptrdiff_t at = (by + r) * pred_stride + bx;
        d[r] = diff8_of_average(src + (by + r) * src_stride + bx, first + at,
                                second ? second + at : nullptr);
      }
      acc = _mm256_add_epi32(acc, satd_pair(d[0], d[1], d[2], d[3]));
    }
  const __m128i v = _mm_add_epi32(_mm256_castsi256_si128(acc), _mm256_extracti128_si256(acc, 1));
  return lane_sum(v) / 2;
}

GVKIT_TARGET_AVX2 void distortions4x4_avx2(bool sad, const __m128i (&rows)[4],
                                           const int32_t (*preds)[16], int count, int64_t* out) {
  if (sad) return distortions4x4_sse2(sad, rows, preds, count, out);
  __m256i s[4];
  for (int r = 0; r < 4; ++r) s[r] = _mm256_broadcastsi128_si256(rows[r]);
  // Pairs of blocks; an odd count's last block is paired with itself.
  for (int i = 0; i < count; i += 2) {
    const int second = i + 1 < count ? i + 1 : i;
    __m256i d[4];
    for (int r = 0; r < 4; ++r) {
      const __m256i p = _mm256_inserti128_si256(
          _mm256_castsi128_si256(
              _mm_loadu_si128(reinterpret_cast<const __m128i*>(preds[i] + 4 * r))),
          _mm_loadu_si128(reinterpret_cast<const __m128i*>(preds[second] + 4 * r)), 1);
      d[r] = _mm256_sub_epi32(s[r], p);
    }
    const __m256i sum = satd_pair(d[0], d[1], d[2], d[3]);
    out[i] = lane_sum(_mm256_castsi256_si128(sum)) / 2;
    if (second != i) out[second] = lane_sum(_mm256_extracti128_si256(sum, 1)) / 2;
  }
}

// AVX-512: four 4x4 blocks at once, one per 128-bit lane, as the AVX2 forms pair two. (GCC 12's
// avx512fintrin.h fills unused operands with a self-initialised _mm512_undefined_epi32, which
// its own -Wuninitialized reports.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
GVKIT_TARGET_AVX512 inline void hadamard4_avx512(__m512i& a, __m512i& b, __m512i& c, __m512i& d) {
  const __m512i a0 = _mm512_add_epi32(a, b), a1 = _mm512_sub_epi32(a, b);
  const __m512i a2 = _mm512_add_epi32(c, d), a3 = _mm512_sub_epi32(c, d);
  a = _mm512_add_epi32(a0, a2);
  b = _mm512_add_epi32(a1, a3);
  c = _mm512_sub_epi32(a0, a2);
  d = _mm512_sub_epi32(a1, a3);
}

// Sum of |coefficients| of the four blocks whose rows are r0..r3, per lane.
GVKIT_TARGET_AVX512 inline __m512i satd_quad(__m512i r0, __m512i r1, __m512i r2, __m512i r3) {
  hadamard4_avx512(r0, r1, r2, r3);
  const __m512i t0 = _mm512_unpacklo_epi32(r0, r1), t1 = _mm512_unpacklo_epi32(r2, r3);
  const __m512i t2 = _mm512_unpackhi_epi32(r0, r1), t3 = _mm512_unpackhi_epi32(r2, r3);
  r0 = _mm512_unpacklo_epi64(t0, t1);
  r1 = _mm512_unpackhi_epi64(t0, t1);
  r2 = _mm512_unpacklo_epi64(t2, t3);
  r3 = _mm512_unpackhi_epi64(t2, t3);
  hadamard4_avx512(r0, r1, r2, r3);
  return _mm512_add_epi32(_mm512_add_epi32(_mm512_abs_epi32(r0), _mm512_abs_epi32(r1)),
                          _mm512_add_epi32(_mm512_abs_epi32(r2), _mm512_abs_epi32(r3)));
}

// Sixteen samples: 16 in a row (n = 16), or 8 of row `a` then 8 of row `b` (n = 8, b = a + 4
// rows: widened, the lower two lanes hold rows 0-3 of the block pair, the upper two rows 4-7).
GVKIT_TARGET_AVX512 inline __m256i samples16(const uint16_t* a, const uint16_t* b, int n) {
  return n == 16 ? _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a))
                 : _mm256_inserti128_si256(
                       _mm256_castsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a))),
                       _mm_loadu_si128(reinterpret_cast<const __m128i*>(b)), 1);
}
GVKIT_TARGET_AVX512 inline __m512i widen16(const uint16_t* a, const uint16_t* b, int n) {
  return _mm512_cvtepu16_epi32(samples16(a, b, n));
}
GVKIT_TARGET_AVX512 inline __m512i load16(const int32_t* a, const int32_t* b, int n) {
  return n == 16
             ? _mm512_loadu_si512(a)
             : _mm512_inserti64x4(
                   _mm512_castsi256_si512(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(a))),
                   _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b)), 1);
}

// n = 8 or 16: the SATD sum of the n x n differences, diff(y) giving row y's sixteen (n = 16) or
// rows y and y + 4 side by side (n = 8). Per lane at most 4 blocks x 16 coefficients < 2^21 each.
template <class RowDifference>
GVKIT_TARGET_AVX512 inline int64_t satd_avx512(int n, const RowDifference& diff) {
  __m512i acc = _mm512_setzero_si512();
  // Rows by..by+3, and for n = 8 also by+4..by+7.
  for (int by = 0; by < n; by += n == 16 ? 4 : 8) {
    const __m512i d0 = diff(by), d1 = diff(by + 1), d2 = diff(by + 2), d3 = diff(by + 3);
    acc = _mm512_add_epi32(acc, satd_quad(d0, d1, d2, d3));
  }
  return _mm512_reduce_add_epi32(acc) / 2;
}

GVKIT_TARGET_AVX512 int64_t satd_block_avx512(int n, const uint16_t* src, ptrdiff_t src_stride,
                                              const int32_t* pred) {
  return satd_avx512(n, [&](int y) GVKIT_TARGET_AVX512 {
    const uint16_t* s = src + y * src_stride;
    const int32_t* p = pred + y * n;
    return _mm512_sub_epi32(widen16(s, s + 4 * src_stride, n), load16(p, p + 4 * n, n));
  });
}

GVKIT_TARGET_AVX512 int64_t satd_block_of_average_avx512(int n, const uint16_t* src,
                                                         ptrdiff_t src_stride,
                                                         const uint16_t* first,
                                                         const uint16_t* second,
                                                         ptrdiff_t pred_stride) {
  return satd_avx512(n, [&](int y) GVKIT_TARGET_AVX512 {
    const uint16_t* s = src + y * src_stride;
    const ptrdiff_t at = y * pred_stride;
    __m256i p = samples16(first + at, first + at + 4 * pred_stride, n);
    if (second)  // the rounded average (pavgw), as the AVX2 form
      p = _mm256_avg_epu16(p, samples16(second + at, second + at + 4 * pred_stride, n));
    return _mm512_sub_epi32(widen16(s, s + 4 * src_stride, n), _mm512_cvtepu16_epi32(p));
  });
}
#pragma GCC diagnostic pop

#else
int64_t satd_block_avx2(int n, const uint16_t* src, ptrdiff_t src_stride, const int32_t* pred) {
  return satd_block_sse2(n, src, src_stride, pred);
}
void distortions4x4_avx2(bool sad, const __m128i (&rows)[4], const int32_t (*preds)[16], int count,
                         int64_t* out) {
  distortions4x4_sse2(sad, rows, preds, count, out);
}
#endif

}  // namespace

int64_t satd_block(int n, const uint16_t* src, ptrdiff_t src_stride, const int32_t* pred) {
#if defined(GVKIT_X86_SIMD)
  if (n != 4 && gvkit::detail::cpu_has_avx512()) return satd_block_avx512(n, src, src_stride, pred);
#endif
  return gvkit::detail::cpu_has_avx2() ? satd_block_avx2(n, src, src_stride, pred)
                                       : satd_block_sse2(n, src, src_stride, pred);
}

int64_t satd_block_of_average(int n, const uint16_t* src, ptrdiff_t src_stride,
                              const uint16_t* first, const uint16_t* second,
                              ptrdiff_t pred_stride) {
#if defined(GVKIT_X86_SIMD)
  if (gvkit::detail::cpu_has_avx512())
    return satd_block_of_average_avx512(n, src, src_stride, first, second, pred_stride);
  if (gvkit::detail::cpu_has_avx2())
    return satd_block_of_average_avx2(n, src, src_stride, first, second, pred_stride);
#endif
  return satd_block_of_average_reference(n, src, src_stride, first, second, pred_stride);
}

void distortions4x4(bool sad, const uint16_t* src, ptrdiff_t src_stride, const int32_t (*preds)[16],
                    int count, int64_t* out) {
  __m128i rows[4];
  source_rows(src, src_stride, rows);
  if (gvkit::detail::cpu_has_avx2())
    distortions4x4_avx2(sad, rows, preds, count, out);
  else
    distortions4x4_sse2(sad, rows, preds, count, out);
}

void distortions4x4_of(bool sad, const int32_t* source, const int32_t (*preds)[16], int count,
                       int64_t* out) {
  __m128i rows[4];
  source_rows(source, rows);
  if (gvkit::detail::cpu_has_avx2())
    distortions4x4_avx2(sad, rows, preds, count, out);
  else
    distortions4x4_sse2(sad, rows, preds, count, out);
}

int64_t sad_block(int n, const uint16_t* src, ptrdiff_t src_stride, const int32_t* pred) {
  __m128i acc = _mm_setzero_si128();
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; x += 4)
      acc = _mm_add_epi32(acc, abs_epi32(diff4(src + y * src_stride + x, pred + y * n + x)));
  // At most 256 * 2^17 = 2^25.
  return horizontal_sum(acc);
}

#else

void distortions4x4(bool sad, const uint16_t* src, ptrdiff_t src_stride, const int32_t (*preds)[16],
                    int count, int64_t* out) {
  for (int i = 0; i < count; ++i)
    out[i] = sad ? sad_block_reference(4, src, src_stride, preds[i])
                 : satd_block_reference(4, src, src_stride, preds[i]);
}

void distortions4x4_of(bool sad, const int32_t* source, const int32_t (*preds)[16], int count,
                       int64_t* out) {
  distortions4x4_of_reference(sad, source, preds, count, out);
}

int64_t sad16x16(const uint16_t* a, ptrdiff_t a_stride, const uint16_t* b, ptrdiff_t b_stride) {
  return sad16x16_reference(a, a_stride, b, b_stride);
}

int64_t satd_block(int n, const uint16_t* src, ptrdiff_t src_stride, const int32_t* pred) {
  return satd_block_reference(n, src, src_stride, pred);
}

int64_t satd_block_of_average(int n, const uint16_t* src, ptrdiff_t src_stride,
                              const uint16_t* first, const uint16_t* second,
                              ptrdiff_t pred_stride) {
  return satd_block_of_average_reference(n, src, src_stride, first, second, pred_stride);
}

int64_t sad_block(int n, const uint16_t* src, ptrdiff_t src_stride, const int32_t* pred) {
  return sad_block_reference(n, src, src_stride, pred);
}

#endif

}  // namespace gvkit::codec
