// H.264 luma sample interpolation (ITU-T H.264 8.4.2.2.1, equations 8-241 .. 8-261) on B-bit
// samples. Intermediate 6-tap sums stay below 52 * 52 * 2^16 < 2^28, so 32 bits suffice.
#include "gvkit/codec/motion_compensation.hpp"

#include <algorithm>
#include <array>

#include "gvkit/core/cpu_features.hpp"
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace gvkit::codec {
namespace {

struct Sampler {
  const SamplePlane& ref;
  int max_value;

  int32_t at(int x, int y) const {
    return ref.at(std::clamp(x, 0, ref.width - 1), std::clamp(y, 0, ref.height - 1));
  }
  int32_t clip(int32_t v) const { return std::clamp(v, 0, max_value); }
  static int32_t tap6(int32_t e, int32_t f, int32_t g, int32_t h, int32_t i, int32_t j) {
    return e - 5 * f + 20 * g + 20 * h - 5 * i + j;
  }
  // Unrounded horizontal 6-tap sum between (x, y) and (x + 1, y): b1 of the standard.
  int32_t b1(int x, int y) const {
    return tap6(at(x - 2, y), at(x - 1, y), at(x, y), at(x + 1, y), at(x + 2, y), at(x + 3, y));
  }
  // Unrounded vertical 6-tap sum between (x, y) and (x, y + 1): h1.
  int32_t h1(int x, int y) const {
    return tap6(at(x, y - 2), at(x, y - 1), at(x, y), at(x, y + 1), at(x, y + 2), at(x, y + 3));
  }
  int32_t b(int x, int y) const { return clip((b1(x, y) + 16) >> 5); }  // half right of (x, y)
  int32_t h(int x, int y) const { return clip((h1(x, y) + 16) >> 5); }  // half below (x, y)
  int32_t j(int x, int y) const {                                       // centre half position
    const int32_t j1 =
        tap6(b1(x, y - 2), b1(x, y - 1), b1(x, y), b1(x, y + 1), b1(x, y + 2), b1(x, y + 3));
    return clip((j1 + 512) >> 10);
  }
};

inline int32_t avg(int32_t a, int32_t b) { return (a + b + 1) >> 1; }

}  // namespace

int32_t interpolate_quarter_sample(const SamplePlane& ref, int xq, int yq, int bit_depth) {
  const Sampler s{ref, (1 << bit_depth) - 1};
  // Floor division (arithmetic shift) keeps fractions in 0..3 for negative positions.
  const int x = xq >> 2, y = yq >> 2, fx = xq & 3, fy = yq & 3;
  // Names as in H.264 figure 8-4: G at (x, y), H right, M below; b, h, j, m (h of x + 1),
  // s (b of y + 1).
  switch (fy * 4 + fx) {
    case 0:
      return s.at(x, y);  // G
    case 1:
      return avg(s.at(x, y), s.b(x, y));  // a
    case 2:
      return s.b(x, y);  // b
    case 3:
      return avg(s.b(x, y), s.at(x + 1, y));  // c
    case 4:
      return avg(s.at(x, y), s.h(x, y));  // d
    case 5:
      return avg(s.b(x, y), s.h(x, y));  // e
    case 6:
      return avg(s.b(x, y), s.j(x, y));  // f
    case 7:
      return avg(s.b(x, y), s.h(x + 1, y));  // g
    case 8:
      return s.h(x, y);  // h
    case 9:
      return avg(s.h(x, y), s.j(x, y));  // i
    case 10:
      return s.j(x, y);  // j
    case 11:
      return avg(s.j(x, y), s.h(x + 1, y));  // k
    case 12:
      return avg(s.at(x, y + 1), s.h(x, y));  // n
    case 13:
      return avg(s.h(x, y), s.b(x, y + 1));  // p
    case 14:
      return avg(s.j(x, y), s.b(x, y + 1));  // q
    default:
      return avg(s.h(x + 1, y), s.b(x, y + 1));  // r
  }
}

namespace {

// Quarter-sample phase 4 fy + fx as the rounded average of two stored samples (or one): plane
// (0 G, 1 b, 2 h, 3 j) and offset (dx, dy) of each, as in the switch of predict_motion_block.
struct PhaseTaps {
  int8_t plane1, dx1, dy1, plane2, dx2, dy2;  // plane2 < 0: the first sample alone
};
constexpr PhaseTaps kPhaseTaps[16] = {
    {0, 0, 0, -1, 0, 0}, {0, 0, 0, 1, 0, 0}, {1, 0, 0, -1, 0, 0}, {1, 0, 0, 0, 1, 0},
    {0, 0, 0, 2, 0, 0},  {1, 0, 0, 2, 0, 0}, {1, 0, 0, 3, 0, 0},  {1, 0, 0, 2, 1, 0},
    {2, 0, 0, -1, 0, 0}, {2, 0, 0, 3, 0, 0}, {3, 0, 0, -1, 0, 0}, {3, 0, 0, 2, 1, 0},
    {0, 0, 1, 2, 0, 0},  {2, 0, 0, 1, 0, 1}, {3, 0, 0, 1, 0, 1},  {2, 1, 0, 1, 0, 1}};

}  // namespace

void predict_motion_block_reference(const SamplePlane& ref, int x0, int y0, int w, int h, int mv_x,
                                    int mv_y, bool quarter_pel, int bit_depth, int32_t* pred) {
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      pred[y * w + x] = motion_sample(ref, x0 + x, y0 + y, mv_x, mv_y, quarter_pel, bit_depth);
}

#if defined(GVKIT_X86_SIMD)
namespace {

// The quarter-sample path of predict_motion_block with eight 32-bit lanes: the same window, the
// same half-sample values and the same integer arithmetic (every 6-tap sum fits 32 bits, as in
// the plain loops), so the same samples; only the planes the phase reads are computed, over the
// rows and whole vectors it reads (the plain loops take (w + 1) x (h + 1) of each). Rows are
// padded to whole vectors: the window to 32 columns (the taps of 24 columns), the planes to 24.
constexpr int kWinStride = 32, kPlaneStride = 24;

GVKIT_TARGET_AVX2 inline __m256i tap6_avx2(__m256i e, __m256i f, __m256i g, __m256i h, __m256i i,
                                           __m256i j) {
  // e - 5 f + 20 g + 20 h - 5 i + j, with shifts: 20 x = 16 x + 4 x, 5 x = 4 x + x.
  const __m256i gh = _mm256_add_epi32(g, h), fi = _mm256_add_epi32(f, i);
  const __m256i twenty = _mm256_add_epi32(_mm256_slli_epi32(gh, 4), _mm256_slli_epi32(gh, 2));
  const __m256i five = _mm256_add_epi32(_mm256_slli_epi32(fi, 2), fi);
  return _mm256_add_epi32(_mm256_add_epi32(e, j), _mm256_sub_epi32(twenty, five));
}

GVKIT_TARGET_AVX2 inline __m256i load8(const int32_t* p) {
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}

GVKIT_TARGET_AVX2 void predict_quarter_block_avx2(const SamplePlane& ref, int x0, int y0, int w,
                                                  int h, int mv_x, int mv_y, int bit_depth,
                                                  int32_t* pred) {
  const int fx = mv_x & 3, fy = mv_y & 3;
  const int xi = x0 + (mv_x >> 2) - 2, yi = y0 + (mv_y >> 2) - 2;
  alignas(32) int32_t win[(kMaxMotionBlock + 6) * kWinStride];
  const auto convert_row = [&](const uint16_t* row, int32_t* out) GVKIT_TARGET_AVX2 {
    for (int x = 0; x < kWinStride; x += 16) {
      const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + x));
      _mm256_store_si256(reinterpret_cast<__m256i*>(out + x),
                         _mm256_cvtepu16_epi32(_mm256_castsi256_si128(v)));
      _mm256_store_si256(reinterpret_cast<__m256i*>(out + x + 8),
                         _mm256_cvtepu16_epi32(_mm256_extracti128_si256(v, 1)));
    }
  };
  if (xi >= 0 && yi >= 0 && xi + kWinStride <= ref.width && yi + h + 6 <= ref.height) {
    for (int y = 0; y < h + 6; ++y)
      convert_row(&ref.samples[static_cast<size_t>(yi + y) * ref.width + xi], win + y * kWinStride);
  } else {
    // Rows clamped to the picture; per row, the columns left of it (x < lo), inside it and right
    // of it (x >= hi).
    const int lo = std::clamp(-xi, 0, kWinStride);
    const int hi = std::clamp(ref.width - xi, lo, kWinStride);
    for (int y = 0; y < h + 6; ++y) {
      const int sy = std::clamp(yi + y, 0, ref.height - 1);
      const uint16_t* row = &ref.samples[static_cast<size_t>(sy) * ref.width];
      int32_t* out = win + y * kWinStride;
      if (lo == 0 && hi == kWinStride) {
        convert_row(row + xi, out);
        continue;
      }
      const int32_t left = row[0], right = row[ref.width - 1];
      int x = 0;
      for (; x < lo; ++x) out[x] = left;
      for (; x < hi; ++x) out[x] = row[xi + x];
      for (; x < kWinStride; ++x) out[x] = right;
    }
  }
  const int phase = fy * 4 + fx;
  const PhaseTaps& t = kPhaseTaps[phase];
  // Per plane (G, b, h, j): whether the phase reads it, and how far right (dx) and down (dy) of
  // the block's samples. A plane is computed over h + dy rows and the vectors whose lanes the
  // combination below reads: its loads start at columns 0, 8, .. below w, plus dx.
  bool need[4] = {};
  int dx[4] = {}, dy[4] = {};
  for (const auto [plane, x, y] :
       {std::array<int, 3>{t.plane1, t.dx1, t.dy1}, std::array<int, 3>{t.plane2, t.dx2, t.dy2}}) {
    if (plane < 0) continue;
    need[plane] = true;
    dx[plane] = std::max(dx[plane], x);
    dy[plane] = std::max(dy[plane], y);
  }
  const auto vectors = [&](int plane) { return (w - 1) / 8 + 1 + dx[plane]; };
  const __m256i zero = _mm256_setzero_si256(), max_value = _mm256_set1_epi32((1 << bit_depth) - 1);
  const __m256i r16 = _mm256_set1_epi32(16), r512 = _mm256_set1_epi32(512);
  alignas(32) int32_t b1[(kMaxMotionBlock + 6) * kPlaneStride];
  alignas(32) int32_t b[(kMaxMotionBlock + 1) * kPlaneStride],
      hh[(kMaxMotionBlock + 1) * kPlaneStride], j[(kMaxMotionBlock + 1) * kPlaneStride];
  if (need[1] || need[3]) {
    // b reads b1's rows 2 .. h + dy + 1, j its rows 0 .. h + dy + 4 (six taps down).
    const int first = need[3] ? 0 : 2;
    const int last = std::max(need[1] ? h + dy[1] + 2 : 0, need[3] ? h + dy[3] + 5 : 0);
    const int columns = std::max(need[1] ? vectors(1) : 0, need[3] ? vectors(3) : 0);
    for (int y = first; y < last; ++y)
      for (int v = 0; v < columns; ++v) {
        const int32_t* s = win + y * kWinStride + 8 * v;
        _mm256_store_si256(reinterpret_cast<__m256i*>(b1 + y * kPlaneStride + 8 * v),
                           tap6_avx2(load8(s), load8(s + 1), load8(s + 2), load8(s + 3),
                                     load8(s + 4), load8(s + 5)));
      }
  }
  const auto clip = [&](__m256i v) GVKIT_TARGET_AVX2 {
    return _mm256_min_epi32(_mm256_max_epi32(v, zero), max_value);
  };
  if (need[1])
    for (int y = 0; y < h + dy[1]; ++y)
      for (int v = 0; v < vectors(1); ++v) {
        const __m256i t1 =
            _mm256_srai_epi32(_mm256_add_epi32(load8(b1 + (y + 2) * kPlaneStride + 8 * v), r16), 5);
        _mm256_store_si256(reinterpret_cast<__m256i*>(b + y * kPlaneStride + 8 * v), clip(t1));
      }
  if (need[2])
    for (int y = 0; y < h + dy[2]; ++y)
      for (int v = 0; v < vectors(2); ++v) {
        const int32_t* s = win + y * kWinStride + 8 * v + 2;
        const __m256i t1 = _mm256_srai_epi32(
            _mm256_add_epi32(tap6_avx2(load8(s), load8(s + kWinStride), load8(s + 2 * kWinStride),
                                       load8(s + 3 * kWinStride), load8(s + 4 * kWinStride),
                                       load8(s + 5 * kWinStride)),
                             r16),
            5);
        _mm256_store_si256(reinterpret_cast<__m256i*>(hh + y * kPlaneStride + 8 * v), clip(t1));
      }
  if (need[3])
    for (int y = 0; y < h + dy[3]; ++y)
      for (int v = 0; v < vectors(3); ++v) {
        const int32_t* s = b1 + y * kPlaneStride + 8 * v;
        const __m256i t1 = _mm256_srai_epi32(
            _mm256_add_epi32(tap6_avx2(load8(s), load8(s + kPlaneStride),
                                       load8(s + 2 * kPlaneStride), load8(s + 3 * kPlaneStride),
                                       load8(s + 4 * kPlaneStride), load8(s + 5 * kPlaneStride)),
                             r512),
            10);
        _mm256_store_si256(reinterpret_cast<__m256i*>(j + y * kPlaneStride + 8 * v), clip(t1));
      }
  const int32_t* const plane_of[4] = {&win[2 * kWinStride + 2], b, hh, j};
  const int stride_of[4] = {kWinStride, kPlaneStride, kPlaneStride, kPlaneStride};
  const int s1 = stride_of[t.plane1];
  const int32_t* p1 = plane_of[t.plane1] + t.dy1 * s1 + t.dx1;
  const int s2 = t.plane2 < 0 ? 0 : stride_of[t.plane2];
  const int32_t* p2 = t.plane2 < 0 ? nullptr : plane_of[t.plane2] + t.dy2 * s2 + t.dx2;
  const __m256i one = _mm256_set1_epi32(1);
  // The last vector of a row keeps its first w % 8 lanes.
  const __m256i tail =
      _mm256_cmpgt_epi32(_mm256_set1_epi32(w % 8), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; x += 8) {
      __m256i v = load8(p1 + y * s1 + x);
      if (p2)
        v = _mm256_srai_epi32(_mm256_add_epi32(_mm256_add_epi32(v, load8(p2 + y * s2 + x)), one),
                              1);
      if (x + 8 <= w)
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(pred + y * w + x), v);
      else
        _mm256_maskstore_epi32(pred + y * w + x, tail, v);
    }
}

}  // namespace
#endif

void predict_motion_block(const SamplePlane& ref, int x0, int y0, int w, int h, int mv_x, int mv_y,
                          bool quarter_pel, int bit_depth, int32_t* pred) {
  GVKIT_CHECK(w > 0 && h > 0 && w <= kMaxMotionBlock && h <= kMaxMotionBlock);
  if (quarter_pel && (mv_x & 3) == 0 && (mv_y & 3) == 0) {
    quarter_pel = false;  // a whole-sample vector: a plain (clamped) copy
    mv_x >>= 2;
    mv_y >>= 2;
  }
  if (!quarter_pel) {
    const int sx = x0 + mv_x, sy = y0 + mv_y;
    if (sx < 0 || sy < 0 || sx + w > ref.width || sy + h > ref.height) {
      predict_motion_block_reference(ref, x0, y0, w, h, mv_x, mv_y, false, bit_depth, pred);
      return;
    }
    for (int y = 0; y < h; ++y) {  // inside the picture: no clamping
      const uint16_t* row = &ref.samples[static_cast<size_t>(sy + y) * ref.width + sx];
      for (int x = 0; x < w; ++x) pred[y * w + x] = row[x];
    }
    return;
  }
#if defined(GVKIT_X86_SIMD)
  if (gvkit::detail::cpu_has_avx2())
    return predict_quarter_block_avx2(ref, x0, y0, w, h, mv_x, mv_y, bit_depth, pred);
#endif
  // Every sample of the block has the same fractional phase: gather the clamped integer window
  // (2 samples left / above, 3 right / below of the (w + 1) x (h + 1) area the positions touch)
  // once, then the half-sample planes b, h, j over that area, then the phase's combination.
  constexpr int kWin = kMaxMotionBlock + 6, kArea = kMaxMotionBlock + 1;
  const int fx = mv_x & 3, fy = mv_y & 3;
  const int xi = x0 + (mv_x >> 2) - 2, yi = y0 + (mv_y >> 2) - 2;
  const int max_value = (1 << bit_depth) - 1;
  const auto clip = [max_value](int32_t v) { return std::clamp(v, 0, max_value); };
  const auto tap6 = [](const int32_t* v, int stride) {
    return v[0] - 5 * v[stride] + 20 * v[2 * stride] + 20 * v[3 * stride] - 5 * v[4 * stride] +
           v[5 * stride];
  };
  int32_t win[kWin * kWin];
  const bool inside = xi >= 0 && yi >= 0 && xi + w + 6 <= ref.width && yi + h + 6 <= ref.height;
  for (int y = 0; y < h + 6; ++y) {
    const int sy = std::clamp(yi + y, 0, ref.height - 1);
    const uint16_t* row = &ref.samples[static_cast<size_t>(sy) * ref.width];
    if (inside)
      for (int x = 0; x < w + 6; ++x) win[y * kWin + x] = row[xi + x];
    else
      for (int x = 0; x < w + 6; ++x) win[y * kWin + x] = row[std::clamp(xi + x, 0, ref.width - 1)];
  }
  // Only the half-sample planes the phase combines (bit c of a mask: phase c = 4 fy + fx uses it).
  const int phase = fy * 4 + fx;
  const bool need_b = (0xE0EE >> phase) & 1, need_h = (0xBBB0 >> phase) & 1,
             need_j = (0x4E40 >> phase) & 1;
  // b1 rows for the area's columns (j needs window rows 0 .. h + 5, b rows 2 .. h + 2).
  int32_t b1[kWin * kArea], b[kArea * kArea], hh[kArea * kArea], j[kArea * kArea];
  if (need_b || need_j) {
    const int first = need_j ? 0 : 2, last = need_j ? h + 6 : h + 3;
    for (int y = first; y < last; ++y)
      for (int x = 0; x <= w; ++x) b1[y * kArea + x] = tap6(&win[y * kWin + x], 1);
  }
  // One plane at a time, so that each loop vectorizes.
  if (need_b)
    for (int y = 0; y <= h; ++y)
      for (int x = 0; x <= w; ++x) b[y * kArea + x] = clip((b1[(y + 2) * kArea + x] + 16) >> 5);
  if (need_h)
    for (int y = 0; y <= h; ++y)
      for (int x = 0; x <= w; ++x)
        hh[y * kArea + x] = clip((tap6(&win[y * kWin + x + 2], kWin) + 16) >> 5);
  if (need_j)
    for (int y = 0; y <= h; ++y)
      for (int x = 0; x <= w; ++x)
        j[y * kArea + x] = clip((tap6(&b1[y * kArea + x], kArea) + 512) >> 10);
  // The phase's one or two samples (kPhaseTaps); G is read from the window itself.
  const int32_t* const plane_of[4] = {&win[2 * kWin + 2], b, hh, j};
  const int stride_of[4] = {kWin, kArea, kArea, kArea};
  const PhaseTaps& t = kPhaseTaps[phase];
  const int s1 = stride_of[t.plane1];
  const int32_t* p1 = plane_of[t.plane1] + t.dy1 * s1 + t.dx1;
  if (t.plane2 < 0) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) pred[y * w + x] = p1[y * s1 + x];
    return;
  }
  const int s2 = stride_of[t.plane2];
  const int32_t* p2 = plane_of[t.plane2] + t.dy2 * s2 + t.dx2;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) pred[y * w + x] = avg(p1[y * s1 + x], p2[y * s2 + x]);
}

InterpolatedReference::InterpolatedReference(const SamplePlane& ref, int bit_depth, int margin)
    : ref_(ref), bit_depth_(bit_depth), margin_(margin), stride_(ref.width + 2 * margin) {
  GVKIT_CHECK(ref.width > 0 && ref.height > 0 && margin >= 0 && bit_depth >= 8 && bit_depth <= 16);
  const int m = margin, pw = ref.width + 2 * m, ph = ref.height + 2 * m;
  const int max_value = (1 << bit_depth) - 1;
  // Rows of the edge-extended whole samples over the padded area plus the filter's reach (2
  // before, 3 after), and their unrounded horizontal sums b1, in rings of the 6 rows the
  // vertical taps read: window row k is picture row k - m - 2.
  const int ew = pw + 5, lead = m + 2;
  constexpr int kRing = 8;
  std::vector<int32_t> e_ring(static_cast<size_t>(kRing) * ew),
      b1_ring(static_cast<size_t>(kRing) * pw);
  const auto make_row = [&](int k) {
    const int sy = std::clamp(k - m - 2, 0, ref.height - 1);
    const uint16_t* row = &ref.samples[static_cast<size_t>(sy) * ref.width];
    int32_t* __restrict out = &e_ring[static_cast<size_t>(k % kRing) * ew];
    std::fill(out, out + lead, row[0]);
    for (int x = 0; x < ref.width; ++x) out[lead + x] = row[x];
    std::fill(out + lead + ref.width, out + ew, row[ref.width - 1]);
    int32_t* __restrict sum = &b1_ring[static_cast<size_t>(k % kRing) * pw];
    for (int x = 0; x < pw; ++x)
      sum[x] =
          out[x] - 5 * out[x + 1] + 20 * out[x + 2] + 20 * out[x + 3] - 5 * out[x + 4] + out[x + 5];
  };
  plane_size_ = static_cast<size_t>(pw) * ph;
  storage_.resize(4 * plane_size_);
  const auto clip = [max_value](int32_t v) {
    return static_cast<uint16_t>(v < 0 ? 0 : (v > max_value ? max_value : v));
  };
  for (int k = 0; k < 5; ++k) make_row(k);
  for (int y = 0; y < ph; ++y) {
    // Padded row y is window row y + 2; the vertical taps read window rows y .. y + 5.
    make_row(y + 5);
    const int32_t* er[6];
    const int32_t* br[6];
    for (int k = 0; k < 6; ++k) {
      er[k] = &e_ring[static_cast<size_t>((y + k) % kRing) * ew + 2];
      br[k] = &b1_ring[static_cast<size_t>((y + k) % kRing) * pw];
    }
    const size_t o = static_cast<size_t>(y) * pw;
    uint16_t* __restrict g = &storage_[o];
    uint16_t* __restrict b = &storage_[plane_size_ + o];
    uint16_t* __restrict h = &storage_[2 * plane_size_ + o];
    uint16_t* __restrict j = &storage_[3 * plane_size_ + o];
    const int32_t* __restrict e0 = er[0], * __restrict e1 = er[1], * __restrict e2 = er[2], * __restrict e3 = er[3], * __restrict e4 = er[4], * __restrict e5 = er[5];
    const int32_t* __restrict s0 = br[0], * __restrict s1 = br[1], * __restrict s2 = br[2], * __restrict s3 = br[3], * __restrict s4 = br[4], * __restrict s5 = br[5];
    for (int x = 0; x < pw; ++x) g[x] = static_cast<uint16_t>(e2[x]);
    for (int x = 0; x < pw; ++x) b[x] = clip((s2[x] + 16) >> 5);
    for (int x = 0; x < pw; ++x)
      h[x] = clip((e0[x] - 5 * e1[x] + 20 * e2[x] + 20 * e3[x] - 5 * e4[x] + e5[x] + 16) >> 5);
    for (int x = 0; x < pw; ++x)
      j[x] = clip((s0[x] - 5 * s1[x] + 20 * s2[x] + 20 * s3[x] - 5 * s4[x] + s5[x] + 512) >> 10);
  }
}

void InterpolatedReference::predict(int x0, int y0, int w, int h, int mv_x, int mv_y,
                                    bool quarter_pel, int32_t* pred) const {
  GVKIT_CHECK(w > 0 && h > 0);
  // Beyond the margin: block-wise interpolation (blocks up to kMaxMotionBlock), else per sample.
  const auto fallback = [&] {
    if (w <= kMaxMotionBlock && h <= kMaxMotionBlock)
      predict_motion_block(ref_, x0, y0, w, h, mv_x, mv_y, quarter_pel, bit_depth_, pred);
    else
      predict_motion_block_reference(ref_, x0, y0, w, h, mv_x, mv_y, quarter_pel, bit_depth_, pred);
  };
  if (!quarter_pel) {
    const int x = x0 + mv_x, y = y0 + mv_y;
    if (!inside(x, y, w, h)) return fallback();
    const uint16_t* g = &storage_[index(x, y)];
    for (int r = 0; r < h; ++r, g += stride_)
      for (int c = 0; c < w; ++c) pred[r * w + c] = g[c];
    return;
  }
  const int xi = x0 + (mv_x >> 2), yi = y0 + (mv_y >> 2);
  if (!inside(xi, yi, w + 1, h + 1)) return fallback();
  const PhaseTaps& t = kPhaseTaps[(mv_y & 3) * 4 + (mv_x & 3)];
  const uint16_t* p1 = &storage_[t.plane1 * plane_size_ + index(xi + t.dx1, yi + t.dy1)];
  if (t.plane2 < 0) {
    for (int r = 0; r < h; ++r, p1 += stride_)
      for (int c = 0; c < w; ++c) pred[r * w + c] = p1[c];
    return;
  }
  const uint16_t* p2 = &storage_[t.plane2 * plane_size_ + index(xi + t.dx2, yi + t.dy2)];
  for (int r = 0; r < h; ++r, p1 += stride_, p2 += stride_) {
    int c = 0;
#if defined(__SSE2__)
    // pavgw is (a + b + 1) >> 1 on unsigned 16-bit samples, without overflow.
    const __m128i zero = _mm_setzero_si128();
    for (; c + 8 <= w; c += 8) {
      const __m128i a = _mm_avg_epu16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p1 + c)),
                                      _mm_loadu_si128(reinterpret_cast<const __m128i*>(p2 + c)));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(pred + r * w + c), _mm_unpacklo_epi16(a, zero));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(pred + r * w + c + 4),
                       _mm_unpackhi_epi16(a, zero));
    }
#endif
    for (; c < w; ++c) pred[r * w + c] = (int32_t{p1[c]} + p2[c] + 1) >> 1;
  }
}

int32_t InterpolatedReference::sample(int x, int y, int mv_x, int mv_y, bool quarter_pel) const {
  if (!quarter_pel) {
    const int sx = x + mv_x, sy = y + mv_y;
    if (!inside(sx, sy, 1, 1)) return motion_sample(ref_, x, y, mv_x, mv_y, false, bit_depth_);
    return storage_[index(sx, sy)];
  }
  const int xi = x + (mv_x >> 2), yi = y + (mv_y >> 2);
  if (!inside(xi, yi, 2, 2)) return motion_sample(ref_, x, y, mv_x, mv_y, true, bit_depth_);
  const PhaseTaps& t = kPhaseTaps[(mv_y & 3) * 4 + (mv_x & 3)];
  const int32_t v1 = storage_[t.plane1 * plane_size_ + index(xi + t.dx1, yi + t.dy1)];
  if (t.plane2 < 0) return v1;
  return (v1 + storage_[t.plane2 * plane_size_ + index(xi + t.dx2, yi + t.dy2)] + 1) >> 1;
}

bool InterpolatedReference::quarter_block_rows(int x0, int y0, int w, int h, int mv_x, int mv_y,
                                               const uint16_t** first,
                                               const uint16_t** second) const {
  const int xi = x0 + (mv_x >> 2), yi = y0 + (mv_y >> 2);
  if (!inside(xi, yi, w + 1, h + 1)) return false;
  const PhaseTaps& t = kPhaseTaps[(mv_y & 3) * 4 + (mv_x & 3)];
  *first = &storage_[t.plane1 * plane_size_ + index(xi + t.dx1, yi + t.dy1)];
  *second =
      t.plane2 < 0 ? nullptr : &storage_[t.plane2 * plane_size_ + index(xi + t.dx2, yi + t.dy2)];
  return true;
}

const uint16_t* InterpolatedReference::whole_block(int x, int y, int w, int h) const {
  return inside(x, y, w, h) ? &storage_[index(x, y)] : nullptr;
}

}  // namespace gvkit::codec
