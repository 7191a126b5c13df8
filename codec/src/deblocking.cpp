#include "gvkit/codec/deblocking.hpp"

#include <algorithm>
#include <cstdlib>

#include "gvkit/core/cpu_features.hpp"

namespace gvkit::codec {
namespace {

// One line across an edge: s points at q0, p_i = s[-(i + 1) step], q_i = s[i step].
inline void filter_line(uint16_t* s, ptrdiff_t step, int64_t beta, int64_t tc, int max_value) {
  const int64_t p0 = s[-step], p1 = s[-2 * step], p2 = s[-3 * step];
  const int64_t q0 = s[0], q1 = s[step], q2 = s[2 * step];
  const int64_t dp = std::abs(p2 - 2 * p1 + p0), dq = std::abs(q2 - 2 * q1 + q0);
  if (dp + dq >= beta) return;
  int64_t delta = (9 * (q0 - p0) - 3 * (q1 - p1) + 8) >> 4;
  if (std::abs(delta) >= 10 * tc) return;  // a real edge of the surface, not blocking
  delta = std::clamp(delta, -tc, tc);
  const auto clip = [max_value](int64_t v) {
    return static_cast<uint16_t>(std::clamp<int64_t>(v, 0, max_value));
  };
  s[-step] = clip(p0 + delta);
  s[0] = clip(q0 - delta);
  const int64_t side = (beta + (beta >> 1)) >> 3, half = tc >> 1;
  if (dp < side)
    s[-2 * step] = clip(p1 + std::clamp((((p2 + p0 + 1) >> 1) - p1 + delta) >> 1, -half, half));
  if (dq < side)
    s[step] = clip(q1 + std::clamp((((q2 + q0 + 1) >> 1) - q1 - delta) >> 1, -half, half));
}

}  // namespace

int64_t deblocking_step16(int qp_prime) {
  static constexpr int64_t kStep16[6] = {10, 11, 13, 14, 16, 18};
  GVKIT_CHECK(qp_prime >= 0 && qp_prime <= 99);
  return kStep16[qp_prime % 6] << (qp_prime / 6);
}

namespace {

// The thresholds of a plane's filter at qp_prime: beta (second differences) and tc1 (the
// clipping of boundary strength 1; strength bs clips at bs * tc1). Checks that the strengths
// cover the plane's 4x4 blocks.
struct DeblockingThresholds {
  int64_t beta = 0, tc1 = 0;
  bool filters() const { return beta > 0 && tc1 > 0; }
};

DeblockingThresholds deblocking_thresholds(const SamplePlane& plane,
                                           const DeblockingStrengths& strengths, int qp_prime,
                                           const DeblockingParams& params) {
  GVKIT_CHECK(plane.width % 8 == 0 && plane.height % 8 == 0 &&
              strengths.blocks_x == plane.width / 4 && strengths.blocks_y == plane.height / 4 &&
              strengths.vertical.size() ==
                  static_cast<size_t>(strengths.blocks_x) * strengths.blocks_y &&
              strengths.horizontal.size() == strengths.vertical.size());
  const int64_t step16 = deblocking_step16(qp_prime);
  return {params.beta * step16 / 64, params.tc * step16 / 256};
}

}  // namespace

#if defined(GVKIT_X86_SIMD)
namespace {

// filter_line on eight lines at once, one per 32-bit lane (every intermediate of filter_line
// fits 32 bits: samples < 2^16, beta < 2^23, 10 tc < 2^25). A lane with tc = 0 (strength 0) is
// left as it is, as |delta| >= 0 = 10 tc.
struct Lines {
  __m256i p2, p1, p0, q0, q1, q2;
};

GVKIT_TARGET_AVX2 inline __m256i clamp_epi32(__m256i v, __m256i lo, __m256i hi) {
  return _mm256_min_epi32(_mm256_max_epi32(v, lo), hi);
}

GVKIT_TARGET_AVX2 inline void filter_lines_avx2(Lines& l, __m256i beta, __m256i side, __m256i tc,
                                                __m256i max_value) {
  const __m256i zero = _mm256_setzero_si256(), one = _mm256_set1_epi32(1);
  const __m256i dp =
      _mm256_abs_epi32(_mm256_add_epi32(_mm256_sub_epi32(l.p2, _mm256_slli_epi32(l.p1, 1)), l.p0));
  const __m256i dq =
      _mm256_abs_epi32(_mm256_add_epi32(_mm256_sub_epi32(l.q2, _mm256_slli_epi32(l.q1, 1)), l.q0));
  const __m256i d0 = _mm256_sub_epi32(l.q0, l.p0), d1 = _mm256_sub_epi32(l.q1, l.p1);
  __m256i delta = _mm256_srai_epi32(
      _mm256_add_epi32(_mm256_sub_epi32(_mm256_add_epi32(_mm256_slli_epi32(d0, 3), d0),
                                        _mm256_add_epi32(_mm256_slli_epi32(d1, 1), d1)),
                       _mm256_set1_epi32(8)),
      4);
  const __m256i ten_tc = _mm256_add_epi32(_mm256_slli_epi32(tc, 3), _mm256_slli_epi32(tc, 1));
  const __m256i filtered = _mm256_and_si256(_mm256_cmpgt_epi32(beta, _mm256_add_epi32(dp, dq)),
                                            _mm256_cmpgt_epi32(ten_tc, _mm256_abs_epi32(delta)));
  if (_mm256_testz_si256(filtered, filtered)) return;
  delta = clamp_epi32(delta, _mm256_sub_epi32(zero, tc), tc);
  const __m256i half = _mm256_srai_epi32(tc, 1), minus_half = _mm256_sub_epi32(zero, half);
  const __m256i p0 = clamp_epi32(_mm256_add_epi32(l.p0, delta), zero, max_value);
  const __m256i q0 = clamp_epi32(_mm256_sub_epi32(l.q0, delta), zero, max_value);
  // p1 + clip((((p2 + p0 + 1) >> 1) - p1 + delta) >> 1, +-half) where dp < side; q1 likewise.
  const __m256i p_avg = _mm256_srai_epi32(_mm256_add_epi32(_mm256_add_epi32(l.p2, l.p0), one), 1);
  const __m256i q_avg = _mm256_srai_epi32(_mm256_add_epi32(_mm256_add_epi32(l.q2, l.q0), one), 1);
  const __m256i p1 = clamp_epi32(
      _mm256_add_epi32(
          l.p1,
          clamp_epi32(_mm256_srai_epi32(_mm256_add_epi32(_mm256_sub_epi32(p_avg, l.p1), delta), 1),
                      minus_half, half)),
      zero, max_value);
  const __m256i q1 = clamp_epi32(
      _mm256_add_epi32(
          l.q1,
          clamp_epi32(_mm256_srai_epi32(_mm256_sub_epi32(_mm256_sub_epi32(q_avg, l.q1), delta), 1),
                      minus_half, half)),
      zero, max_value);
  const __m256i p_side = _mm256_and_si256(filtered, _mm256_cmpgt_epi32(side, dp));
  const __m256i q_side = _mm256_and_si256(filtered, _mm256_cmpgt_epi32(side, dq));
  l.p0 = _mm256_blendv_epi8(l.p0, p0, filtered);
  l.q0 = _mm256_blendv_epi8(l.q0, q0, filtered);
  l.p1 = _mm256_blendv_epi8(l.p1, p1, p_side);
  l.q1 = _mm256_blendv_epi8(l.q1, q1, q_side);
}

GVKIT_TARGET_AVX2 inline __m256i load_u16x8(const uint16_t* p) {
  return _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
}

GVKIT_TARGET_AVX2 inline __m128i pack_u16x8(__m256i v) {
  return _mm_packus_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
}

GVKIT_TARGET_AVX2 inline void store_u16x8(uint16_t* p, __m256i v) {
  _mm_storeu_si128(reinterpret_cast<__m128i*>(p), pack_u16x8(v));
}

// The eight 16-bit lanes of eight rows, transposed (SSE2 unpacks): out[k] holds element k of
// every row.
GVKIT_TARGET_AVX2 inline void transpose8x8_u16(const __m128i in[8], __m128i out[8]) {
  const __m128i a0 = _mm_unpacklo_epi16(in[0], in[1]), a1 = _mm_unpackhi_epi16(in[0], in[1]);
  const __m128i a2 = _mm_unpacklo_epi16(in[2], in[3]), a3 = _mm_unpackhi_epi16(in[2], in[3]);
  const __m128i a4 = _mm_unpacklo_epi16(in[4], in[5]), a5 = _mm_unpackhi_epi16(in[4], in[5]);
  const __m128i a6 = _mm_unpacklo_epi16(in[6], in[7]), a7 = _mm_unpackhi_epi16(in[6], in[7]);
  const __m128i b0 = _mm_unpacklo_epi32(a0, a2), b1 = _mm_unpackhi_epi32(a0, a2);
  const __m128i b2 = _mm_unpacklo_epi32(a1, a3), b3 = _mm_unpackhi_epi32(a1, a3);
  const __m128i b4 = _mm_unpacklo_epi32(a4, a6), b5 = _mm_unpackhi_epi32(a4, a6);
  const __m128i b6 = _mm_unpacklo_epi32(a5, a7), b7 = _mm_unpackhi_epi32(a5, a7);
  out[0] = _mm_unpacklo_epi64(b0, b4);
  out[1] = _mm_unpackhi_epi64(b0, b4);
  out[2] = _mm_unpacklo_epi64(b1, b5);
  out[3] = _mm_unpackhi_epi64(b1, b5);
  out[4] = _mm_unpacklo_epi64(b2, b6);
  out[5] = _mm_unpackhi_epi64(b2, b6);
  out[6] = _mm_unpacklo_epi64(b3, b7);
  out[7] = _mm_unpackhi_epi64(b3, b7);
}

GVKIT_TARGET_AVX2 void deblock_plane_avx2(SamplePlane& plane, const DeblockingStrengths& strengths,
                                          int32_t beta, int32_t tc1, int max_value) {
  const int bx = strengths.blocks_x, by = strengths.blocks_y;
  const ptrdiff_t stride = plane.width;
  const __m256i beta_v = _mm256_set1_epi32(beta),
                side_v = _mm256_set1_epi32((beta + (beta >> 1)) >> 3),
                max_v = _mm256_set1_epi32(max_value);
  // Vertical edges, eight rows (two 4x4 blocks, each with its strength) at a time: the eight
  // samples around the edge of each row (p3 .. q3, columns x - 4 .. x + 3, touched by no other
  // edge) transposed into lanes, filtered, transposed back.
  for (int gy = 0; gy < by; gy += 2)
    for (int gx = 2; gx < bx; gx += 2) {
      const size_t i = static_cast<size_t>(gy) * bx + gx;
      const int bs0 = strengths.vertical[i], bs1 = gy + 1 < by ? strengths.vertical[i + bx] : 0;
      if (bs0 == 0 && bs1 == 0) continue;
      const int rows = gy + 1 < by ? 8 : 4;
      uint16_t* s = &plane.samples[static_cast<size_t>(gy) * 4 * stride + gx * 4 - 4];
      __m128i in[8], t[8];
      for (int r = 0; r < 8; ++r)
        in[r] = r < rows ? _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + r * stride))
                         : _mm_setzero_si128();
      transpose8x8_u16(in, t);
      Lines l{_mm256_cvtepu16_epi32(t[1]), _mm256_cvtepu16_epi32(t[2]),
              _mm256_cvtepu16_epi32(t[3]), _mm256_cvtepu16_epi32(t[4]),
              _mm256_cvtepu16_epi32(t[5]), _mm256_cvtepu16_epi32(t[6])};
      const __m256i tc = _mm256_setr_epi32(bs0 * tc1, bs0 * tc1, bs0 * tc1, bs0 * tc1, bs1 * tc1,
                                           bs1 * tc1, bs1 * tc1, bs1 * tc1);
      filter_lines_avx2(l, beta_v, side_v, tc, max_v);
      t[2] = pack_u16x8(l.p1);
      t[3] = pack_u16x8(l.p0);
      t[4] = pack_u16x8(l.q0);
      t[5] = pack_u16x8(l.q1);
      transpose8x8_u16(t, in);
      for (int r = 0; r < rows; ++r)
        _mm_storeu_si128(reinterpret_cast<__m128i*>(s + r * stride), in[r]);
    }
  // Horizontal edges, eight columns (two 4x4 blocks) at a time along the edge.
  for (int gy = 2; gy < by; gy += 2)
    for (int gx = 0; gx < bx; gx += 2) {
      const size_t i = static_cast<size_t>(gy) * bx + gx;
      const int bs0 = strengths.horizontal[i], bs1 = gx + 1 < bx ? strengths.horizontal[i + 1] : 0;
      if (bs0 == 0 && bs1 == 0) continue;
      uint16_t* s = &plane.samples[static_cast<size_t>(gy) * 4 * stride + gx * 4];
      Lines l{load_u16x8(s - 3 * stride), load_u16x8(s - 2 * stride),
              load_u16x8(s - stride),     load_u16x8(s),
              load_u16x8(s + stride),     load_u16x8(s + 2 * stride)};
      const __m256i tc = _mm256_setr_epi32(bs0 * tc1, bs0 * tc1, bs0 * tc1, bs0 * tc1, bs1 * tc1,
                                           bs1 * tc1, bs1 * tc1, bs1 * tc1);
      filter_lines_avx2(l, beta_v, side_v, tc, max_v);
      store_u16x8(s - 2 * stride, l.p1);
      store_u16x8(s - stride, l.p0);
      store_u16x8(s, l.q0);
      store_u16x8(s + stride, l.q1);
    }
}

}  // namespace
#endif

void deblock_plane(SamplePlane& plane, const DeblockingStrengths& strengths, int qp_prime,
                   int bit_depth, const DeblockingParams& params) {
#if defined(GVKIT_X86_SIMD)
  if (gvkit::detail::cpu_has_avx2()) {
    const DeblockingThresholds t = deblocking_thresholds(plane, strengths, qp_prime, params);
    if (!t.filters()) return;
    deblock_plane_avx2(plane, strengths, static_cast<int32_t>(t.beta), static_cast<int32_t>(t.tc1),
                       (1 << bit_depth) - 1);
    return;
  }
#endif
  deblock_plane_reference(plane, strengths, qp_prime, bit_depth, params);
}

void deblock_plane_reference(SamplePlane& plane, const DeblockingStrengths& strengths, int qp_prime,
                             int bit_depth, const DeblockingParams& params) {
  const DeblockingThresholds t = deblocking_thresholds(plane, strengths, qp_prime, params);
  if (!t.filters()) return;
  const int64_t beta = t.beta, tc1 = t.tc1;
  const int max_value = (1 << bit_depth) - 1;
  const int bx = strengths.blocks_x, by = strengths.blocks_y;
  const ptrdiff_t stride = plane.width;
  for (int gy = 0; gy < by; ++gy)
    for (int gx = 2; gx < bx; gx += 2) {
      const int bs = strengths.vertical[static_cast<size_t>(gy) * bx + gx];
      if (bs == 0) continue;
      uint16_t* s = &plane.samples[static_cast<size_t>(gy) * 4 * stride + gx * 4];
      for (int k = 0; k < 4; ++k) filter_line(s + k * stride, 1, beta, bs * tc1, max_value);
    }
  for (int gy = 2; gy < by; gy += 2)
    for (int gx = 0; gx < bx; ++gx) {
      const int bs = strengths.horizontal[static_cast<size_t>(gy) * bx + gx];
      if (bs == 0) continue;
      uint16_t* s = &plane.samples[static_cast<size_t>(gy) * 4 * stride + gx * 4];
      for (int k = 0; k < 4; ++k) filter_line(s + k, stride, beta, bs * tc1, max_value);
    }
}

}  // namespace gvkit::codec
