#include "gvkit/codec/geometry_planes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "gvkit/core/cpu_features.hpp"

namespace gvkit::codec {
namespace {

int padded(int n) { return (n + 15) / 16 * 16; }

// std::round (halves away from zero) without the library call: below 2^52 the truncation is
// exact through int64 and so is q - trunc(q); from 2^52 on every double is an integer.
inline double round_half_away(double q) {
  if (!(std::abs(q) < 4503599627370496.0)) return q;
  const double t = static_cast<double>(static_cast<int64_t>(q));
  const double f = q - t;
  // Branch-free (the fraction is unpredictable): adding 1.0 or 0.0 to an integer is exact.
  return t + static_cast<double>(f >= 0.5) - static_cast<double>(f <= -0.5);
}

// A sample's value: q rounded (halves away from zero) and clamped to [0, max_value]; 0 where q
// is not finite.
inline double rounded_sample(double q, double max_value) {
  return std::isfinite(q) ? std::clamp(round_half_away(q), 0.0, max_value) : 0.0;
}

#if defined(GVKIT_X86_SIMD)
// round_half_away of four values, clamped to [0, top], with the scalar's operations (truncation,
// the fraction's two tests, the clamp), exact in double (from 2^52 on the truncation is the value
// itself). A NaN lane gives 0 or top: callers mask or avoid them.
GVKIT_TARGET_AVX2 inline __m256d round_half_away_clamped_avx2(__m256d v, __m256d top) {
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256d t = _mm256_round_pd(v, _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC);
  const __m256d f = _mm256_sub_pd(v, t);
  __m256d r =
      _mm256_add_pd(t, _mm256_and_pd(_mm256_cmp_pd(f, _mm256_set1_pd(0.5), _CMP_GE_OQ), one));
  r = _mm256_sub_pd(r, _mm256_and_pd(_mm256_cmp_pd(f, _mm256_set1_pd(-0.5), _CMP_LE_OQ), one));
  return _mm256_min_pd(_mm256_max_pd(r, _mm256_setzero_pd()), top);
}
#endif

// Whether the AVX2 rows run: where the processor has AVX2, unless the plain version is asked for.
inline bool use_avx2(bool plain) {
#if defined(GVKIT_X86_SIMD)
  return !plain && gvkit::detail::cpu_has_avx2();
#else
  (void)plain;
  return false;
#endif
}

// Push-pull on (value * weight, weight) images: returns the filled values.
void push_pull(std::vector<double>& v, std::vector<double>& w, int width, int height) {
  if (width <= 1 && height <= 1) {
    if (w[0] > 0) v[0] /= w[0];
    return;
  }
  const int cw = (width + 1) / 2, ch = (height + 1) / 2;
  std::vector<double> cv_(static_cast<size_t>(cw) * ch, 0.0), cwt(cv_.size(), 0.0);
  // Each coarse cell sums its pixels row by row, left to right.
  for (int y = 0; y < height; ++y) {
    const double* vr = &v[static_cast<size_t>(y) * width];
    const double* wr = &w[static_cast<size_t>(y) * width];
    double* cvr = &cv_[static_cast<size_t>(y / 2) * cw];
    double* cwr = &cwt[static_cast<size_t>(y / 2) * cw];
    int x = 0;
    for (; x + 2 <= width; x += 2) {
      cvr[x / 2] = (cvr[x / 2] + vr[x]) + vr[x + 1];
      cwr[x / 2] = (cwr[x / 2] + wr[x]) + wr[x + 1];
    }
    if (x < width) {
      cvr[x / 2] += vr[x];
      cwr[x / 2] += wr[x];
    }
  }
  push_pull(cv_, cwt, cw, ch);
  // Bilinear weights from the coarse level at each pixel's centre, per column and per row.
  struct Tap {
    int i0, i1;
    double a;
  };
  std::vector<Tap> col(static_cast<size_t>(width)), row(static_cast<size_t>(height));
  for (int x = 0; x < width; ++x) {
    const double fx = std::clamp((x + 0.5) / 2 - 0.5, 0.0, cw - 1.0);
    const int x0 = static_cast<int>(fx);
    col[x] = {x0, std::min(x0 + 1, cw - 1), fx - x0};
  }
  for (int y = 0; y < height; ++y) {
    const double fy = std::clamp((y + 0.5) / 2 - 0.5, 0.0, ch - 1.0);
    const int y0 = static_cast<int>(fy);
    row[y] = {y0, std::min(y0 + 1, ch - 1), fy - y0};
  }
  for (int y = 0; y < height; ++y) {
    const double* c0 = &cv_[static_cast<size_t>(row[y].i0) * cw];
    const double* c1 = &cv_[static_cast<size_t>(row[y].i1) * cw];
    const double ay = row[y].a;
    double* vr = &v[static_cast<size_t>(y) * width];
    const double* wr = &w[static_cast<size_t>(y) * width];
    for (int x = 0; x < width; ++x) {
      if (wr[x] > 0) {
        if (wr[x] != 1.0) vr[x] /= wr[x];  // x / 1 is x exactly: skip most of the divisions
        continue;
      }
      const Tap& t = col[x];
      const double ax = t.a;
      vr[x] = (1 - ay) * ((1 - ax) * c0[t.i0] + ax * c0[t.i1]) +
              ay * ((1 - ax) * c1[t.i0] + ax * c1[t.i1]);
    }
  }
}

}  // namespace

namespace {

// One sample of to_plane: v rounded (halves away from zero) and clamped to [0, max_value].
inline uint16_t to_sample(double v, int max_value) {
  // std::lround's value wherever it is defined (|v| < 2^52 here: v mixes samples in range).
  const long r =
      std::abs(v) < 4503599627370496.0 ? static_cast<long>(round_half_away(v)) : std::lround(v);
  return static_cast<uint16_t>(std::clamp<long>(r, 0, max_value));
}

void to_plane_rows_reference(const double* values, int width, int height, int max_value,
                             SamplePlane& p) {
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      p.at(x, y) = to_sample(values[static_cast<size_t>(y) * width + x], max_value);
}

#if defined(GVKIT_X86_SIMD)
// Four values of |v| < 2^31 at a time (round_half_away_clamped_avx2); a group with a value outside
// that range (or not a number) takes the scalar path.
GVKIT_TARGET_AVX2 void to_plane_rows_avx2(const double* values, int width, int height,
                                          int max_value, SamplePlane& p) {
  const __m256d sign = _mm256_set1_pd(-0.0), limit = _mm256_set1_pd(2147483648.0),
                top = _mm256_set1_pd(static_cast<double>(max_value));
  for (int y = 0; y < height; ++y) {
    const double* in = values + static_cast<size_t>(y) * width;
    uint16_t* out = &p.samples[static_cast<size_t>(y) * p.width];
    int x = 0;
    for (; x + 4 <= width; x += 4) {
      const __m256d v = _mm256_loadu_pd(in + x);
      if (_mm256_movemask_pd(_mm256_cmp_pd(_mm256_andnot_pd(sign, v), limit, _CMP_LT_OQ)) != 15) {
        for (int k = 0; k < 4; ++k) out[x + k] = to_sample(in[x + k], max_value);
        continue;
      }
      const __m128i i32 = _mm256_cvttpd_epi32(round_half_away_clamped_avx2(v, top));
      _mm_storel_epi64(reinterpret_cast<__m128i*>(out + x), _mm_packus_epi32(i32, i32));
    }
    for (; x < width; ++x) out[x] = to_sample(in[x], max_value);
  }
}
#endif

// Pads p beyond width x height by repeating the last column and row.
void pad_plane(int width, int height, SamplePlane& p) {
  for (int y = 0; y < height; ++y)
    for (int x = width; x < p.width; ++x) p.at(x, y) = p.at(width - 1, y);
  for (int y = height; y < p.height; ++y)
    std::copy_n(&p.samples[static_cast<size_t>(height - 1) * p.width], p.width,
                &p.samples[static_cast<size_t>(y) * p.width]);
}

// to_plane, its rows by AVX2 where the processor has it unless `plain`.
SamplePlane make_plane(const std::vector<double>& values, int width, int height, int max_value,
                       bool plain) {
  SamplePlane p;
  p.width = padded(width);
  p.height = padded(height);
  p.samples.resize(static_cast<size_t>(p.width) * p.height);
#if defined(GVKIT_X86_SIMD)
  if (use_avx2(plain))
    to_plane_rows_avx2(values.data(), width, height, max_value, p);
  else
#endif
    to_plane_rows_reference(values.data(), width, height, max_value, p);
  pad_plane(width, height, p);
  return p;
}

// Quantizes axis `axis` of a row of xyz pixels into row[0, width): the position's steps from
// box_min, rounded (halves away from zero) and clamped to [0, max_value]; 0 where not finite.
void quantize_row_reference(const float* xyz, int axis, int width, double box_min, double step,
                            int max_value, double* row) {
  const float* p = xyz + axis;
  // The divisions first, in a loop the compiler vectorizes, then the rounding.
  for (int x = 0; x < width; ++x) row[x] = (p[3 * x] - box_min) / step;
  for (int x = 0; x < width; ++x) row[x] = rounded_sample(row[x], max_value);
}

#if defined(GVKIT_X86_SIMD)
// The same operations four pixels at a time: the float widened, the difference and quotient in
// double, round_half_away_clamped_avx2, 0 where not finite.
GVKIT_TARGET_AVX2 void quantize_row_avx2(const float* xyz, int axis, int width, double box_min,
                                         double step, int max_value, double* row) {
  const float* p = xyz + axis;
  const __m256d min_v = _mm256_set1_pd(box_min), step_v = _mm256_set1_pd(step),
                sign = _mm256_set1_pd(-0.0),
                infinity = _mm256_set1_pd(std::numeric_limits<double>::infinity()),
                top = _mm256_set1_pd(static_cast<double>(max_value));
  int x = 0;
  for (; x + 4 <= width; x += 4) {
    const __m128 f4 = _mm_setr_ps(p[3 * x], p[3 * x + 3], p[3 * x + 6], p[3 * x + 9]);
    const __m256d q = _mm256_div_pd(_mm256_sub_pd(_mm256_cvtps_pd(f4), min_v), step_v);
    const __m256d finite = _mm256_cmp_pd(_mm256_andnot_pd(sign, q), infinity, _CMP_LT_OQ);
    _mm256_storeu_pd(row + x, _mm256_and_pd(round_half_away_clamped_avx2(q, top), finite));
  }
  for (; x < width; ++x) row[x] = rounded_sample((p[3 * x] - box_min) / step, max_value);
}
#endif

// quantize_geometry, plain (the reference) or with the AVX2 rows where the processor has them.
std::vector<SamplePlane> quantize_geometry_with(const GeometryImage& image,
                                                const SequenceInfo& info, bool plain) {
  GVKIT_CHECK(image.xyz_mm.type() == CV_32FC3 && image.xyz_mm.rows == info.height &&
              image.xyz_mm.cols == info.width);
  const int w = info.width, h = info.height;
  const double step = info.step_mm();
  const int max_value = (1 << info.bit_depth) - 1;
  std::vector<SamplePlane> planes;
  std::vector<double> values(static_cast<size_t>(w) * h);
  for (int a = 0; a < 3; ++a) {
    for (int y = 0; y < h; ++y) {
      const float* xyz = image.xyz_mm.ptr<float>(y);
      double* row = &values[static_cast<size_t>(y) * w];
#if defined(GVKIT_X86_SIMD)
      if (use_avx2(plain)) {
        quantize_row_avx2(xyz, a, w, info.box_min_mm[a], step, max_value, row);
        continue;
      }
#endif
      quantize_row_reference(xyz, a, w, info.box_min_mm[a], step, max_value, row);
    }
    fill_outside_domain(values, w, h, info.domain_mask);
    planes.push_back(make_plane(values, w, h, max_value, plain));
  }
  if (info.has_texture) {
    const bool texture = !image.texture.empty();
    for (int y = 0; y < h; ++y) {
      const float* row = texture ? image.texture.ptr<float>(y) : nullptr;
      for (int x = 0; x < w; ++x) {
        const float t = texture ? row[x] : 0.f;
        values[static_cast<size_t>(y) * w + x] = rounded_sample(t * 255.0, 255.0);
      }
    }
    planes.push_back(make_plane(values, w, h, 255, plain));
  }
  return planes;
}

}  // namespace

SamplePlane to_plane(const std::vector<double>& values, int width, int height, int max_value) {
  return make_plane(values, width, height, max_value, false);
}

void fill_outside_domain(std::vector<double>& values, int width, int height, const cv::Mat& mask) {
  std::vector<double> weights(values.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      weights[i] = mask.at<uint8_t>(y, x) ? 1.0 : 0.0;
      values[i] *= weights[i];
    }
  push_pull(values, weights, width, height);
}

std::vector<SamplePlane> quantize_geometry(const GeometryImage& image, const SequenceInfo& info) {
  return quantize_geometry_with(image, info, false);
}

std::vector<SamplePlane> quantize_geometry_reference(const GeometryImage& image,
                                                     const SequenceInfo& info) {
  return quantize_geometry_with(image, info, true);
}

namespace {

// The image's values (xyz, texture) of the planes, one row at a time.
void dequantize_rows_reference(const std::vector<SamplePlane>& planes, const SequenceInfo& info,
                               GeometryImage& image) {
  const double step = info.step_mm();
  for (int y = 0; y < info.height; ++y) {
    cv::Vec3f* p = image.xyz_mm.ptr<cv::Vec3f>(y);
    for (int x = 0; x < info.width; ++x)
      for (int a = 0; a < 3; ++a)
        p[x][a] = static_cast<float>(info.box_min_mm[a] + planes[a].at(x, y) * step);
  }
  if (!image.texture.empty())
    for (int y = 0; y < info.height; ++y)
      for (int x = 0; x < info.width; ++x)
        image.texture.at<float>(y, x) = planes[3].at(x, y) / 255.0f;
}

#if defined(GVKIT_X86_SIMD)
// AVX2 with the same operations on every value (a double product and sum, one rounding to
// float; a float quotient), so bit for bit the reference. No FMA: it would round once.
GVKIT_TARGET_AVX2 void dequantize_rows_avx2(const std::vector<SamplePlane>& planes,
                                            const SequenceInfo& info, GeometryImage& image) {
  const int width = info.width;
  const double step_mm = info.step_mm();  // (no call between the vector instructions)
  const __m256d step = _mm256_set1_pd(step_mm);
  std::vector<float> axis_rows(3 * (static_cast<size_t>(width) + 8));
  const size_t axis_stride = static_cast<size_t>(width) + 8;
  for (int y = 0; y < info.height; ++y) {
    for (int a = 0; a < 3; ++a) {
      const __m256d box_min = _mm256_set1_pd(info.box_min_mm[a]);
      const uint16_t* in = &planes[a].samples[static_cast<size_t>(y) * planes[a].width];
      float* out = &axis_rows[a * axis_stride];
      int x = 0;
      for (; x + 8 <= width; x += 8) {
        const __m256i q =
            _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(in + x)));
        const __m256d lo = _mm256_add_pd(
            box_min, _mm256_mul_pd(_mm256_cvtepi32_pd(_mm256_castsi256_si128(q)), step));
        const __m256d hi = _mm256_add_pd(
            box_min, _mm256_mul_pd(_mm256_cvtepi32_pd(_mm256_extracti128_si256(q, 1)), step));
        _mm_storeu_ps(out + x, _mm256_cvtpd_ps(lo));
        _mm_storeu_ps(out + x + 4, _mm256_cvtpd_ps(hi));
      }
      for (; x < width; ++x) out[x] = static_cast<float>(info.box_min_mm[a] + in[x] * step_mm);
    }
    float* p = image.xyz_mm.ptr<float>(y);
    const float *ax = &axis_rows[0], *ay = &axis_rows[axis_stride],
                *az = &axis_rows[2 * axis_stride];
    int x = 0;
    // Eight pixels' x, y and z interleaved into 24 floats: each output vector takes three or
    // two lanes of each axis (permuted into place), blended.
    const __m256i x0 = _mm256_setr_epi32(0, 0, 0, 1, 0, 0, 2, 0),
                  y0 = _mm256_setr_epi32(0, 0, 0, 0, 1, 0, 0, 2),
                  z0 = _mm256_setr_epi32(0, 0, 0, 0, 0, 1, 0, 0),
                  x1 = _mm256_setr_epi32(0, 3, 0, 0, 4, 0, 0, 5),
                  y1 = _mm256_setr_epi32(0, 0, 3, 0, 0, 4, 0, 0),
                  z1 = _mm256_setr_epi32(2, 0, 0, 3, 0, 0, 4, 0),
                  x2 = _mm256_setr_epi32(0, 0, 6, 0, 0, 7, 0, 0),
                  y2 = _mm256_setr_epi32(5, 0, 0, 6, 0, 0, 7, 0),
                  z2 = _mm256_setr_epi32(0, 5, 0, 0, 6, 0, 0, 7);
    for (; x + 8 <= width; x += 8) {
      const __m256 vx = _mm256_loadu_ps(ax + x), vy = _mm256_loadu_ps(ay + x),
                   vz = _mm256_loadu_ps(az + x);
      // Lanes of y: 0b10010010 (out 0), 0b00100100 (1), 0b01001001 (2); of z: 0b00100100,
      // 0b01001001, 0b10010010.
      const __m256 o0 = _mm256_blend_ps(
          _mm256_blend_ps(_mm256_permutevar8x32_ps(vx, x0), _mm256_permutevar8x32_ps(vy, y0), 0x92),
          _mm256_permutevar8x32_ps(vz, z0), 0x24);
      const __m256 o1 = _mm256_blend_ps(
          _mm256_blend_ps(_mm256_permutevar8x32_ps(vx, x1), _mm256_permutevar8x32_ps(vy, y1), 0x24),
          _mm256_permutevar8x32_ps(vz, z1), 0x49);
      const __m256 o2 = _mm256_blend_ps(
          _mm256_blend_ps(_mm256_permutevar8x32_ps(vx, x2), _mm256_permutevar8x32_ps(vy, y2), 0x49),
          _mm256_permutevar8x32_ps(vz, z2), 0x92);
      _mm256_storeu_ps(p + 3 * x, o0);
      _mm256_storeu_ps(p + 3 * x + 8, o1);
      _mm256_storeu_ps(p + 3 * x + 16, o2);
    }
    for (; x < width; ++x) {
      p[3 * x] = ax[x];
      p[3 * x + 1] = ay[x];
      p[3 * x + 2] = az[x];
    }
  }
  if (image.texture.empty()) return;
  const __m256 scale = _mm256_set1_ps(255.0f);
  for (int y = 0; y < info.height; ++y) {
    const uint16_t* in = &planes[3].samples[static_cast<size_t>(y) * planes[3].width];
    float* out = image.texture.ptr<float>(y);
    int x = 0;
    for (; x + 8 <= width; x += 8) {
      const __m256i q =
          _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(in + x)));
      _mm256_storeu_ps(out + x, _mm256_div_ps(_mm256_cvtepi32_ps(q), scale));
    }
    for (; x < width; ++x) out[x] = in[x] / 255.0f;
  }
}
#endif

void dequantize_geometry_with(void (*rows)(const std::vector<SamplePlane>&, const SequenceInfo&,
                                           GeometryImage&),
                              const std::vector<SamplePlane>& planes, const SequenceInfo& info,
                              int64_t frame_number, GeometryImage& image) {
  GVKIT_CHECK(planes.size() >= 3);
  for (size_t a = 0; a < planes.size() && a < 4; ++a)
    GVKIT_CHECK(planes[a].width >= info.width && planes[a].height >= info.height);
  image.xyz_mm.create(info.height, info.width, CV_32FC3);
  if (info.has_texture && planes.size() >= 4)
    image.texture.create(info.height, info.width, CV_32F);
  else
    image.texture.release();
  rows(planes, info, image);
  image.domain_mask = info.domain_mask.clone();
  image.index = frame_number;
  image.timestamp = Timestamp(static_cast<int64_t>(std::llround(frame_number * 1e9 / info.fps)));
}

}  // namespace

void dequantize_geometry_into(const std::vector<SamplePlane>& planes, const SequenceInfo& info,
                              int64_t frame_number, GeometryImage& image) {
#if defined(GVKIT_X86_SIMD)
  if (gvkit::detail::cpu_has_avx2())
    return dequantize_geometry_with(dequantize_rows_avx2, planes, info, frame_number, image);
#endif
  dequantize_geometry_with(dequantize_rows_reference, planes, info, frame_number, image);
}

GeometryImage dequantize_geometry(const std::vector<SamplePlane>& planes, const SequenceInfo& info,
                                  int64_t frame_number) {
  GeometryImage image;
  dequantize_geometry_into(planes, info, frame_number, image);
  return image;
}

GeometryImage dequantize_geometry_reference(const std::vector<SamplePlane>& planes,
                                            const SequenceInfo& info, int64_t frame_number) {
  GeometryImage image;
  dequantize_geometry_with(dequantize_rows_reference, planes, info, frame_number, image);
  return image;
}

}  // namespace gvkit::codec
