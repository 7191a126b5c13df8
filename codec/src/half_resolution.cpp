#include "gvkit/codec/half_resolution.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/core/cpu_features.hpp"

namespace gvkit::codec {
namespace {

int padded(int n) { return (n + 15) / 16 * 16; }

// Repeats the last coded column and row into the padding.
void pad_plane(SamplePlane& p, int width, int height) {
  for (int y = 0; y < height; ++y) {
    uint16_t* row = &p.samples[static_cast<size_t>(y) * p.width];
    std::fill(row + width, row + p.width, row[width - 1]);
  }
  const uint16_t* last = &p.samples[static_cast<size_t>(height - 1) * p.width];
  for (int y = height; y < p.height; ++y)
    std::copy(last, last + p.width, &p.samples[static_cast<size_t>(y) * p.width]);
}

// Tap k (0..3) of full-resolution pixel `out` and the half-resolution sample it weighs (clamped
// to [0, n - 1]).
struct Tap {
  int sample, weight;
};
Tap tap(int out, int k, int n) {
  const int i = out / 2;
  if (out % 2 == 1) return {std::clamp(i - 1 + k, 0, n - 1), kHalfUpsampleTaps[k]};
  return {std::clamp(i - 2 + k, 0, n - 1), kHalfUpsampleTaps[3 - k]};
}

// The four taps of every one of n_full pixels over n samples.
std::vector<std::array<Tap, 4>> taps_of(int n_full, int n) {
  std::vector<std::array<Tap, 4>> taps(n_full);
  for (int out = 0; out < n_full; ++out)
    for (int k = 0; k < 4; ++k) taps[out][k] = tap(out, k, n);
  return taps;
}

// Least-squares halving along one axis of n_full pixels: the m = half_size(n_full) samples z
// minimising |U z - x|^2, U the 1-D upsampling operator, by the normal equations
// (U^T U) z = U^T x. U^T U is banded (a pixel's four taps span four samples: |i - j| <= 3), so
// its Cholesky factor is too and every line costs O(n).
class LeastSquaresHalving {
 public:
  explicit LeastSquaresHalving(int n_full)
      : n_(n_full), m_(half_size(n_full)), l_(m_), taps_(taps_of(n_full, m_)) {
    std::vector<std::array<double, 4>> normal(m_, {0, 0, 0, 0});  // normal[i][d] = N(i, i - d)
    for (const std::array<Tap, 4>& t : taps_)
      for (const Tap& ta : t)
        for (const Tap& tb : t) {
          if (ta.sample >= tb.sample)
            normal[ta.sample][ta.sample - tb.sample] += ta.weight * tb.weight / 4096.0;
        }
    for (int i = 0; i < m_; ++i)
      for (int j = std::max(0, i - 3); j <= i; ++j) {
        double sum = normal[i][i - j];
        for (int k = std::max(0, i - 3); k < j; ++k) sum -= l_[i][i - k] * l_[j][j - k];
        l_[i][i - j] = i == j ? std::sqrt(std::max(sum, 1e-12)) : sum / l_[j][0];
      }
  }

  // The m x cols samples z (row-major) of the n x cols pixels x: every column of x halved, all
  // columns at once (contiguous rows).
  void apply(const double* x, int cols, double* z) const {
    std::fill(z, z + static_cast<size_t>(m_) * cols, 0.0);
    for (int out = 0; out < n_; ++out) {  // z = U^T x
      const double* xr = x + static_cast<size_t>(out) * cols;
      for (const Tap& t : taps_[out]) {
        double* zr = z + static_cast<size_t>(t.sample) * cols;
        const double w = t.weight / 64.0;
        for (int c = 0; c < cols; ++c) zr[c] += w * xr[c];
      }
    }
    const auto row = [&](int i) { return z + static_cast<size_t>(i) * cols; };
    for (int i = 0; i < m_; ++i) {  // L y = z
      double* zi = row(i);
      for (int k = std::max(0, i - 3); k < i; ++k) {
        const double l = l_[i][i - k];
        const double* zk = row(k);
        for (int c = 0; c < cols; ++c) zi[c] -= l * zk[c];
      }
      const double inv = 1.0 / l_[i][0];
      for (int c = 0; c < cols; ++c) zi[c] *= inv;
    }
    for (int i = m_ - 1; i >= 0; --i) {  // L^T z = y
      double* zi = row(i);
      for (int k = i + 1; k <= std::min(m_ - 1, i + 3); ++k) {
        const double l = l_[k][k - i];
        const double* zk = row(k);
        for (int c = 0; c < cols; ++c) zi[c] -= l * zk[c];
      }
      const double inv = 1.0 / l_[i][0];
      for (int c = 0; c < cols; ++c) zi[c] *= inv;
    }
  }

 private:
  int n_, m_;
  std::vector<std::array<double, 4>> l_;  // l_[i][d] = L(i, i - d), the Cholesky factor
  std::vector<std::array<Tap, 4>> taps_;  // the four taps of every pixel
};

}  // namespace

SamplePlane upsample_half_plane_reference(const SamplePlane& half, int width, int height,
                                          int bit_depth) {
  const int w = half_size(width), h = half_size(height);
  GVKIT_CHECK(half.width >= w && half.height >= h);
  // The four taps of every output column and row, computed once.
  const auto columns = taps_of(width, w), rows_taps = taps_of(height, h);
  std::vector<int32_t> rows(static_cast<size_t>(width) * h);  // horizontal pass, x64
  for (int y = 0; y < h; ++y) {
    const uint16_t* in = &half.samples[static_cast<size_t>(y) * half.width];
    int32_t* row = &rows[static_cast<size_t>(y) * width];
    for (int x = 0; x < width; ++x) {
      const std::array<Tap, 4>& t = columns[x];
      row[x] = t[0].weight * in[t[0].sample] + t[1].weight * in[t[1].sample] +
               t[2].weight * in[t[2].sample] + t[3].weight * in[t[3].sample];
    }
  }
  SamplePlane out;
  out.width = padded(width);
  out.height = padded(height);
  out.samples.assign(static_cast<size_t>(out.width) * out.height, 0);
  const int64_t max_value = (int64_t{1} << bit_depth) - 1;
  for (int y = 0; y < height; ++y) {
    const std::array<Tap, 4>& t = rows_taps[y];
    const int32_t* r[4];
    for (int k = 0; k < 4; ++k) r[k] = &rows[static_cast<size_t>(t[k].sample) * width];
    uint16_t* o = &out.samples[static_cast<size_t>(y) * out.width];
    for (int x = 0; x < width; ++x) {
      const int64_t sum = int64_t{t[0].weight} * r[0][x] + int64_t{t[1].weight} * r[1][x] +
                          int64_t{t[2].weight} * r[2][x] + int64_t{t[3].weight} * r[3][x];
      o[x] = static_cast<uint16_t>(std::clamp<int64_t>((sum + 2048) >> 12, 0, max_value));
    }
  }
  pad_plane(out, width, height);
  return out;
}

#if defined(GVKIT_X86_SIMD)
namespace {

// AVX2, bit for bit the reference: both passes are exact integer sums, and 32 bits hold them
// (|horizontal| <= 76 x 65535, |vertical| <= 76^2 x 65535 < 2^29; 76 = the sum of |taps|).
GVKIT_TARGET_AVX2 SamplePlane upsample_half_plane_avx2(const SamplePlane& half, int width,
                                                       int height, int bit_depth) {
  const int w = half_size(width), h = half_size(height);
  GVKIT_CHECK(half.width >= w && half.height >= h);
  const int w8 = (w + 7) / 8 * 8;
  // Horizontal pass, x64: output pixels 2i and 2i + 1 of input sample i, eight i at a time from
  // a row with its edge samples repeated (2 before, the rest after), so that no index clamps.
  const int row_stride = (2 * w + 15) / 16 * 16;  // >= width, whole vectors
  std::vector<int32_t> rows(static_cast<size_t>(row_stride) * h);
  std::vector<int32_t> padded_row(static_cast<size_t>(w8) + 8);
  // Allocations and the vertical taps first: library code called after 256-bit instructions
  // (without vzeroupper) would run with the upper register halves in use, which costs.
  SamplePlane out;
  out.width = padded(width);
  out.height = padded(height);
  out.samples.resize(static_cast<size_t>(out.width) * out.height);
  const auto row_taps = taps_of(height, h);
  const __m256i t0 = _mm256_set1_epi32(kHalfUpsampleTaps[0]),
                t1 = _mm256_set1_epi32(kHalfUpsampleTaps[1]),
                t2 = _mm256_set1_epi32(kHalfUpsampleTaps[2]),
                t3 = _mm256_set1_epi32(kHalfUpsampleTaps[3]);
  for (int y = 0; y < h; ++y) {
    const uint16_t* in = &half.samples[static_cast<size_t>(y) * half.width];
    int32_t* pr = padded_row.data();  // pr[j + 2] = in[clamp(j)]
    pr[0] = pr[1] = in[0];
    for (int j = 0; j < w; ++j) pr[j + 2] = in[j];
    for (int j = w + 2; j < w8 + 8; ++j) pr[j] = in[w - 1];
    int32_t* out = &rows[static_cast<size_t>(y) * row_stride];
    for (int i = 0; i < w; i += 8) {
      // Samples i - 2 + k .. i + 5 + k for k = 0..4.
      const __m256i* v = reinterpret_cast<const __m256i*>(pr + i);
      const __m256i am2 = _mm256_loadu_si256(v),
                    am1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pr + i + 1)),
                    a0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pr + i + 2)),
                    a1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pr + i + 3)),
                    a2 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pr + i + 4));
      // Pixel 2i: taps 3, 2, 1, 0 over samples i - 2 .. i + 1; pixel 2i + 1: taps 0..3 over
      // samples i - 1 .. i + 2.
      const __m256i even = _mm256_add_epi32(
          _mm256_add_epi32(_mm256_mullo_epi32(am2, t3), _mm256_mullo_epi32(am1, t2)),
          _mm256_add_epi32(_mm256_mullo_epi32(a0, t1), _mm256_mullo_epi32(a1, t0)));
      const __m256i odd = _mm256_add_epi32(
          _mm256_add_epi32(_mm256_mullo_epi32(am1, t0), _mm256_mullo_epi32(a0, t1)),
          _mm256_add_epi32(_mm256_mullo_epi32(a1, t2), _mm256_mullo_epi32(a2, t3)));
      const __m256i lo = _mm256_unpacklo_epi32(even, odd), hi = _mm256_unpackhi_epi32(even, odd);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + 2 * i),
                          _mm256_permute2x128_si256(lo, hi, 0x20));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + 2 * i + 8),
                          _mm256_permute2x128_si256(lo, hi, 0x31));
    }
  }
  // Vertical pass: rounded, clamped, eight pixels at a time (the last vector of a row may write
  // into the padding, which pad_plane overwrites).
  const __m256i round = _mm256_set1_epi32(2048), zero = _mm256_setzero_si256(),
                max_value = _mm256_set1_epi32((1 << bit_depth) - 1);
  for (int y = 0; y < height; ++y) {
    const std::array<Tap, 4>& t = row_taps[y];
    const int32_t* r[4];
    __m256i wt[4];
    for (int k = 0; k < 4; ++k) {
      r[k] = &rows[static_cast<size_t>(t[k].sample) * row_stride];
      wt[k] = _mm256_set1_epi32(t[k].weight);
    }
    uint16_t* o = &out.samples[static_cast<size_t>(y) * out.width];
    for (int x = 0; x < width; x += 8) {
      __m256i term[4];
      for (int k = 0; k < 4; ++k)
        term[k] = _mm256_mullo_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(r[k] + x)),
                                     wt[k]);
      __m256i sum =
          _mm256_add_epi32(_mm256_add_epi32(term[0], term[1]), _mm256_add_epi32(term[2], term[3]));
      sum = _mm256_srai_epi32(_mm256_add_epi32(sum, round), 12);
      sum = _mm256_min_epi32(_mm256_max_epi32(sum, zero), max_value);
      const __m256i packed = _mm256_permute4x64_epi64(_mm256_packus_epi32(sum, sum), 0x08);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(o + x), _mm256_castsi256_si128(packed));
    }
  }
  pad_plane(out, width, height);
  return out;
}

}  // namespace
#endif

SamplePlane upsample_half_plane(const SamplePlane& half, int width, int height, int bit_depth) {
#if defined(GVKIT_X86_SIMD)
  if (gvkit::detail::cpu_has_avx2())
    return upsample_half_plane_avx2(half, width, height, bit_depth);
#endif
  return upsample_half_plane_reference(half, width, height, bit_depth);
}

SamplePlane downsample_plane(const SamplePlane& full, int width, int height, int bit_depth) {
  const int w = half_size(width), h = half_size(height);
  std::vector<double> x(static_cast<size_t>(width) * height);
  for (int y = 0; y < height; ++y)
    for (int i = 0; i < width; ++i) x[static_cast<size_t>(y) * width + i] = full.at(i, y);
  // Separable: columns (height -> h), then rows (width -> w) as the columns of the transpose.
  std::vector<double> columns(static_cast<size_t>(h) * width), transposed(columns.size());
  LeastSquaresHalving(height).apply(x.data(), width, columns.data());
  for (int y = 0; y < h; ++y)
    for (int i = 0; i < width; ++i)
      transposed[static_cast<size_t>(i) * h + y] = columns[static_cast<size_t>(y) * width + i];
  std::vector<double> low_t(static_cast<size_t>(w) * h);  // w x h
  LeastSquaresHalving(width).apply(transposed.data(), h, low_t.data());
  std::vector<double> low(low_t.size());  // h x w
  for (int i = 0; i < w; ++i)
    for (int y = 0; y < h; ++y)
      low[static_cast<size_t>(y) * w + i] = low_t[static_cast<size_t>(i) * h + y];
  return to_plane(low, w, h, (1 << bit_depth) - 1);
}

SamplePlane halve_plane_mean(const SamplePlane& full, int width, int height) {
  const int w = half_size(width), h = half_size(height);
  GVKIT_CHECK(full.width >= width && full.height >= height);
  SamplePlane out;
  out.width = padded(w);
  out.height = padded(h);
  out.samples.assign(static_cast<size_t>(out.width) * out.height, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int x0 = 2 * x, x1 = std::min(2 * x + 1, width - 1);
      const int y0 = 2 * y, y1 = std::min(2 * y + 1, height - 1);
      const uint32_t sum =
          uint32_t{full.at(x0, y0)} + full.at(x1, y0) + full.at(x0, y1) + full.at(x1, y1) + 2;
      out.at(x, y) = static_cast<uint16_t>(sum >> 2);
    }
  pad_plane(out, w, h);
  return out;
}

cv::Mat half_domain_mask(const cv::Mat& mask) {
  cv::Mat half(half_size(mask.rows), half_size(mask.cols), CV_8U, cv::Scalar(0));
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x)
      if (mask.at<uint8_t>(y, x)) half.at<uint8_t>(y / 2, x / 2) = 255;
  return half;
}

double domain_mse(const std::vector<SamplePlane>& a, const std::vector<SamplePlane>& b,
                  const cv::Mat& mask) {
  double sum = 0;
  int64_t count = 0;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x)
      if (mask.at<uint8_t>(y, x)) {
        ++count;
        for (int p = 0; p < 3; ++p) {
          const double d = static_cast<double>(a[p].at(x, y)) - b[p].at(x, y);
          sum += d * d;
        }
      }
  return count ? sum / (3.0 * static_cast<double>(count)) : 0.0;
}

}  // namespace gvkit::codec
