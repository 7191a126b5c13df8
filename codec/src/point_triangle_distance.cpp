#include "gvkit/codec/point_triangle_distance.hpp"

#include <algorithm>
#include <cmath>

#include "cpu_features.hpp"

namespace gvkit::codec {

double point_triangle_distance2(const cv::Vec3d& p, const cv::Vec3d& a, const cv::Vec3d& b,
                                const cv::Vec3d& c) {
  using Vec3 = cv::Vec3d;
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.dot(ap);
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.dot(bp);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const Vec3 q = a + ab * (d1 / (d1 - d3));
    return (p - q).dot(p - q);
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.dot(cp);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const Vec3 q = a + ac * (d2 / (d2 - d6));
    return (p - q).dot(p - q);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const Vec3 q = b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    return (p - q).dot(p - q);
  }
  const double denom = 1.0 / (va + vb + vc);
  if (!std::isfinite(denom)) {  // degenerate triangle: the nearest of its corners
    return std::min({ap.dot(ap), bp.dot(bp), cp.dot(cp)});
  }
  const Vec3 q = a + ab * (vb * denom) + ac * (vc * denom);
  return (p - q).dot(p - q);
}

double nearest_triangle_distance2_reference(const cv::Vec3d& p, const VertexArrays& v,
                                            const TriangleIndices& t, int n, double bound) {
  const auto at = [&](int32_t i) { return cv::Vec3d(v.x[i], v.y[i], v.z[i]); };
  double best = bound;
  for (int k = 0; k < n; ++k) {
    const double d2 = point_triangle_distance2(p, at(t.a[k]), at(t.b[k]), at(t.c[k]));
    if (d2 < best) best = d2;
  }
  return best;
}

#if defined(GVKIT_X86_SIMD)
namespace {

// Four lanes of three coordinates.
struct V3 {
  __m256d x, y, z;
};

GVKIT_TARGET_AVX2 inline V3 sub(const V3& a, const V3& b) {
  return {_mm256_sub_pd(a.x, b.x), _mm256_sub_pd(a.y, b.y), _mm256_sub_pd(a.z, b.z)};
}
GVKIT_TARGET_AVX2 inline V3 add(const V3& a, const V3& b) {
  return {_mm256_add_pd(a.x, b.x), _mm256_add_pd(a.y, b.y), _mm256_add_pd(a.z, b.z)};
}
GVKIT_TARGET_AVX2 inline V3 scale(const V3& a, __m256d s) {
  return {_mm256_mul_pd(a.x, s), _mm256_mul_pd(a.y, s), _mm256_mul_pd(a.z, s)};
}
// cv::Vec3d::dot: ((0 + x x') + y y') + z z', the zero kept for the sign of a zero result.
GVKIT_TARGET_AVX2 inline __m256d dot(const V3& a, const V3& b) {
  __m256d s = _mm256_add_pd(_mm256_setzero_pd(), _mm256_mul_pd(a.x, b.x));
  s = _mm256_add_pd(s, _mm256_mul_pd(a.y, b.y));
  return _mm256_add_pd(s, _mm256_mul_pd(a.z, b.z));
}
GVKIT_TARGET_AVX2 inline __m256d distance2(const V3& p, const V3& q) {
  const V3 pq = sub(p, q);
  return dot(pq, pq);
}
GVKIT_TARGET_AVX2 inline __m256d le0(__m256d a) {
  return _mm256_cmp_pd(a, _mm256_setzero_pd(), _CMP_LE_OQ);
}
GVKIT_TARGET_AVX2 inline __m256d ge0(__m256d a) {
  return _mm256_cmp_pd(a, _mm256_setzero_pd(), _CMP_GE_OQ);
}
GVKIT_TARGET_AVX2 inline __m256d and3(__m256d a, __m256d b, __m256d c) {
  return _mm256_and_pd(_mm256_and_pd(a, b), c);
}
GVKIT_TARGET_AVX2 inline V3 gather(const VertexArrays& v, __m128i idx) {
  // The masked form with a defined source (the plain one leaves GCC warning about it).
  const __m256d zero = _mm256_setzero_pd(), all = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  return {_mm256_mask_i32gather_pd(zero, v.x, idx, all, 8),
          _mm256_mask_i32gather_pd(zero, v.y, idx, all, 8),
          _mm256_mask_i32gather_pd(zero, v.z, idx, all, 8)};
}

GVKIT_TARGET_AVX2 inline __m128i load4(const int32_t* i) {
  return _mm_loadu_si128(reinterpret_cast<const __m128i*>(i));
}

// point_triangle_distance2 of four triangles at once: every region's candidate computed as the
// scalar code computes it, then the first region that holds chosen per lane.
GVKIT_TARGET_AVX2 inline __m256d point_triangle_distance2_x4(const V3& p, const V3& a, const V3& b,
                                                             const V3& c) {
  const V3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const __m256d d1 = dot(ab, ap), d2 = dot(ac, ap);
  const V3 bp = sub(p, b);
  const __m256d d3 = dot(ab, bp), d4 = dot(ac, bp);
  const __m256d vc = _mm256_sub_pd(_mm256_mul_pd(d1, d4), _mm256_mul_pd(d3, d2));
  const V3 cp = sub(p, c);
  const __m256d d5 = dot(ab, cp), d6 = dot(ac, cp);
  const __m256d vb = _mm256_sub_pd(_mm256_mul_pd(d5, d2), _mm256_mul_pd(d1, d6));
  const __m256d va = _mm256_sub_pd(_mm256_mul_pd(d3, d6), _mm256_mul_pd(d5, d4));
  const __m256d d43 = _mm256_sub_pd(d4, d3), d56 = _mm256_sub_pd(d5, d6);

  const __m256d ap2 = dot(ap, ap), bp2 = dot(bp, bp), cp2 = dot(cp, cp);
  const __m256d on_ab = distance2(p, add(a, scale(ab, _mm256_div_pd(d1, _mm256_sub_pd(d1, d3)))));
  const __m256d on_ac = distance2(p, add(a, scale(ac, _mm256_div_pd(d2, _mm256_sub_pd(d2, d6)))));
  const __m256d on_bc =
      distance2(p, add(b, scale(sub(c, b), _mm256_div_pd(d43, _mm256_add_pd(d43, d56)))));
  const __m256d denom =
      _mm256_div_pd(_mm256_set1_pd(1.0), _mm256_add_pd(_mm256_add_pd(va, vb), vc));
  const __m256d inside = distance2(
      p, add(add(a, scale(ab, _mm256_mul_pd(vb, denom))), scale(ac, _mm256_mul_pd(vc, denom))));
  const __m256d abs_denom = _mm256_andnot_pd(_mm256_set1_pd(-0.0), denom);
  const __m256d finite = _mm256_cmp_pd(abs_denom, _mm256_set1_pd(HUGE_VAL), _CMP_LT_OQ);
  const __m256d corners = _mm256_min_pd(_mm256_min_pd(ap2, bp2), cp2);

  // The scalar code's tests in reverse order, so that the first one that holds wins.
  __m256d r = _mm256_blendv_pd(corners, inside, finite);
  r = _mm256_blendv_pd(r, on_bc, and3(le0(va), ge0(d43), ge0(d56)));
  r = _mm256_blendv_pd(r, on_ac, and3(le0(vb), ge0(d2), le0(d6)));
  r = _mm256_blendv_pd(r, cp2, _mm256_and_pd(ge0(d6), _mm256_cmp_pd(d5, d6, _CMP_LE_OQ)));
  r = _mm256_blendv_pd(r, on_ab, and3(le0(vc), ge0(d1), le0(d3)));
  r = _mm256_blendv_pd(r, bp2, _mm256_and_pd(ge0(d3), _mm256_cmp_pd(d4, d3, _CMP_LE_OQ)));
  return _mm256_blendv_pd(r, ap2, _mm256_and_pd(le0(d1), le0(d2)));
}

GVKIT_TARGET_AVX2 double nearest_triangle_distance2_avx2(const cv::Vec3d& p, const VertexArrays& v,
                                                         const TriangleIndices& t, int n,
                                                         double bound) {
  const V3 pv{_mm256_set1_pd(p[0]), _mm256_set1_pd(p[1]), _mm256_set1_pd(p[2])};
  __m256d best = _mm256_set1_pd(bound);
  int k = 0;
  for (; k + 4 <= n; k += 4) {
    const __m256d d2 = point_triangle_distance2_x4(
        pv, gather(v, load4(t.a + k)), gather(v, load4(t.b + k)), gather(v, load4(t.c + k)));
    // min_pd(d2, best) is "d2 < best ? d2 : best", as in the scalar code: a NaN distance (a
    // degenerate edge's 0 / 0) is never taken.
    best = _mm256_min_pd(d2, best);
  }
  if (k < n) {
    // The last 1-3 triangles: lanes past n load index 0 and their distance is not taken.
    const __m128i lanes = _mm_cmplt_epi32(_mm_setr_epi32(0, 1, 2, 3), _mm_set1_epi32(n - k));
    const __m256d d2 =
        point_triangle_distance2_x4(pv, gather(v, _mm_maskload_epi32(t.a + k, lanes)),
                                    gather(v, _mm_maskload_epi32(t.b + k, lanes)),
                                    gather(v, _mm_maskload_epi32(t.c + k, lanes)));
    best = _mm256_blendv_pd(best, _mm256_min_pd(d2, best),
                            _mm256_castsi256_pd(_mm256_cvtepi32_epi64(lanes)));
  }
  const __m128d m = _mm_min_pd(_mm256_castpd256_pd128(best), _mm256_extractf128_pd(best, 1));
  return _mm_cvtsd_f64(_mm_min_sd(m, _mm_unpackhi_pd(m, m)));
}

}  // namespace
#endif

double nearest_triangle_distance2(const cv::Vec3d& p, const VertexArrays& v,
                                  const TriangleIndices& t, int n, double bound) {
#if defined(GVKIT_X86_SIMD)
  if (detail::cpu_has_avx2()) return nearest_triangle_distance2_avx2(p, v, t, n, bound);
#endif
  return nearest_triangle_distance2_reference(p, v, t, n, bound);
}

}  // namespace gvkit::codec
