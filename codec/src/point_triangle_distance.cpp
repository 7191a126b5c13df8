#include "gvkit/codec/point_triangle_distance.hpp"

#include <algorithm>
#include <cmath>

#include "gvkit/core/cpu_features.hpp"

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

uint32_t spheres_within_reach_reference(const cv::Vec3d& p, const SphereArrays& s, int n,
                                        double reach) {
  uint32_t bits = 0;
  for (int k = 0; k < n; ++k) {
    const cv::Vec3d pq = p - cv::Vec3d(s.x[k], s.y[k], s.z[k]);
    const double limit = s.radius[k] + reach;
    if (s.radius[k] >= 0 && pq.dot(pq) < limit * limit) bits |= 1u << k;
  }
  return bits;
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
// The coordinates of four vertices, by plain loads: faster here than the gather instruction (76
// against 85 ns per eight triangles in codec_surface_metrics_benchmark), which is also much
// slower on processors with the microcode mitigation of gather data sampling.
GVKIT_TARGET_AVX2 inline V3 gather(const VertexArrays& v, const int32_t* i) {
  return {_mm256_setr_pd(v.x[i[0]], v.x[i[1]], v.x[i[2]], v.x[i[3]]),
          _mm256_setr_pd(v.y[i[0]], v.y[i[1]], v.y[i[2]], v.y[i[3]]),
          _mm256_setr_pd(v.z[i[0]], v.z[i[1]], v.z[i[2]], v.z[i[3]])};
}

GVKIT_TARGET_AVX2 inline V3 blend(const V3& a, const V3& b, __m256d mask) {
  return {_mm256_blendv_pd(a.x, b.x, mask), _mm256_blendv_pd(a.y, b.y, mask),
          _mm256_blendv_pd(a.z, b.z, mask)};
}

// point_triangle_distance2 of four triangles at once. Each lane's region is decided first, by
// the scalar code's tests; then one division serves every lane: an edge region's nearest point
// is base + direction * (numerator / denominator) with the scalar code's operands, the
// interior's is a + ab * (vb * d) + ac * (vc * d) with d = 1 / (va + vb + vc); the other regions'
// lanes add +0, which changes no bit of p - q.
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

  const __m256d in_a = _mm256_and_pd(le0(d1), le0(d2));
  const __m256d in_b = _mm256_and_pd(ge0(d3), _mm256_cmp_pd(d4, d3, _CMP_LE_OQ));
  const __m256d in_ab = and3(le0(vc), ge0(d1), le0(d3));
  const __m256d in_c = _mm256_and_pd(ge0(d6), _mm256_cmp_pd(d5, d6, _CMP_LE_OQ));
  const __m256d in_ac = and3(le0(vb), ge0(d2), le0(d6));
  const __m256d in_bc = and3(le0(va), ge0(d43), ge0(d56));

  // The scalar code's tests in reverse order, so that the first one that holds wins.
  const __m256d zero = _mm256_setzero_pd();
  __m256d num = _mm256_set1_pd(1.0);
  __m256d den = _mm256_add_pd(_mm256_add_pd(va, vb), vc);
  V3 base = a, dir = ab;
  num = _mm256_blendv_pd(num, d43, in_bc);
  den = _mm256_blendv_pd(den, _mm256_add_pd(d43, d56), in_bc);
  base = blend(base, b, in_bc);
  dir = blend(dir, sub(c, b), in_bc);
  num = _mm256_blendv_pd(num, d2, in_ac);
  den = _mm256_blendv_pd(den, _mm256_sub_pd(d2, d6), in_ac);
  base = blend(base, a, in_ac);
  dir = blend(dir, ac, in_ac);
  __m256d vertex = _mm256_blendv_pd(zero, dot(cp, cp), in_c);
  __m256d at_vertex = in_c;
  num = _mm256_blendv_pd(num, d1, in_ab);
  den = _mm256_blendv_pd(den, _mm256_sub_pd(d1, d3), in_ab);
  base = blend(base, a, in_ab);
  dir = blend(dir, ab, in_ab);
  at_vertex = _mm256_andnot_pd(in_ab, at_vertex);
  vertex = _mm256_blendv_pd(vertex, dot(bp, bp), in_b);
  at_vertex = _mm256_or_pd(at_vertex, in_b);
  vertex = _mm256_blendv_pd(vertex, dot(ap, ap), in_a);
  at_vertex = _mm256_or_pd(at_vertex, in_a);
  const __m256d interior =
      _mm256_andnot_pd(_mm256_or_pd(_mm256_or_pd(in_bc, in_ac), _mm256_or_pd(in_ab, at_vertex)),
                       _mm256_castsi256_pd(_mm256_set1_epi64x(-1)));

  const __m256d r = _mm256_div_pd(num, den);
  const __m256d t = _mm256_blendv_pd(r, _mm256_mul_pd(vb, r), interior);
  const V3 q = add(add(base, scale(dir, t)),
                   blend({zero, zero, zero}, scale(ac, _mm256_mul_pd(vc, r)), interior));
  const __m256d on_triangle = distance2(p, q);
  // Interior lanes whose 1 / (va + vb + vc) is not finite: a degenerate triangle, the nearest of
  // its corners.
  const __m256d abs_r = _mm256_andnot_pd(_mm256_set1_pd(-0.0), r);
  const __m256d degenerate =
      _mm256_andnot_pd(_mm256_cmp_pd(abs_r, _mm256_set1_pd(HUGE_VAL), _CMP_LT_OQ), interior);
  const __m256d corners = _mm256_min_pd(_mm256_min_pd(dot(ap, ap), dot(bp, bp)), dot(cp, cp));
  const __m256d result = _mm256_blendv_pd(on_triangle, corners, degenerate);
  return _mm256_blendv_pd(result, vertex, at_vertex);
}

GVKIT_TARGET_AVX2 double nearest_triangle_distance2_avx2(const cv::Vec3d& p, const VertexArrays& v,
                                                         const TriangleIndices& t, int n,
                                                         double bound) {
  const V3 pv{_mm256_set1_pd(p[0]), _mm256_set1_pd(p[1]), _mm256_set1_pd(p[2])};
  __m256d best = _mm256_set1_pd(bound);
  int k = 0;
  for (; k + 4 <= n; k += 4) {
    const __m256d d2 =
        point_triangle_distance2_x4(pv, gather(v, t.a + k), gather(v, t.b + k), gather(v, t.c + k));
    // min_pd(d2, best) is "d2 < best ? d2 : best", as in the scalar code: a NaN distance (a
    // degenerate edge's 0 / 0) is never taken.
    best = _mm256_min_pd(d2, best);
  }
  if (k < n) {
    // The last 1-3 triangles: lanes past n load index 0 and their distance is not taken.
    int32_t ia[4] = {0, 0, 0, 0}, ib[4] = {0, 0, 0, 0}, ic[4] = {0, 0, 0, 0};
    for (int lane = 0; k + lane < n; ++lane) {
      ia[lane] = t.a[k + lane];
      ib[lane] = t.b[k + lane];
      ic[lane] = t.c[k + lane];
    }
    const __m256d d2 = point_triangle_distance2_x4(pv, gather(v, ia), gather(v, ib), gather(v, ic));
    const __m256d lanes = _mm256_castsi256_pd(
        _mm256_cmpgt_epi64(_mm256_set1_epi64x(n - k), _mm256_setr_epi64x(0, 1, 2, 3)));
    best = _mm256_blendv_pd(best, _mm256_min_pd(d2, best), lanes);
  }
  const __m128d m = _mm_min_pd(_mm256_castpd256_pd128(best), _mm256_extractf128_pd(best, 1));
  return _mm_cvtsd_f64(_mm_min_sd(m, _mm_unpackhi_pd(m, m)));
}

GVKIT_TARGET_AVX2 inline uint32_t spheres_within_reach_x4(const V3& p, const V3& centre,
                                                          __m256d radius, __m256d reach) {
  const __m256d d2 = distance2(p, centre);
  const __m256d limit = _mm256_add_pd(radius, reach);
  const __m256d within =
      _mm256_and_pd(ge0(radius), _mm256_cmp_pd(d2, _mm256_mul_pd(limit, limit), _CMP_LT_OQ));
  return static_cast<uint32_t>(_mm256_movemask_pd(within));
}

GVKIT_TARGET_AVX2 uint32_t spheres_within_reach_avx2(const cv::Vec3d& p, const SphereArrays& s,
                                                     int n, double reach) {
  const V3 pv{_mm256_set1_pd(p[0]), _mm256_set1_pd(p[1]), _mm256_set1_pd(p[2])};
  const __m256d r = _mm256_set1_pd(reach);
  uint32_t bits = 0;
  int k = 0;
  for (; k + 4 <= n; k += 4)
    bits |= spheres_within_reach_x4(
                pv, {_mm256_loadu_pd(s.x + k), _mm256_loadu_pd(s.y + k), _mm256_loadu_pd(s.z + k)},
                _mm256_loadu_pd(s.radius + k), r)
            << k;
  if (k < n) {
    // The last 1-3 spheres: lanes past n read nothing and count as empty (radius -1).
    const __m256i lanes =
        _mm256_cmpgt_epi64(_mm256_set1_epi64x(n - k), _mm256_setr_epi64x(0, 1, 2, 3));
    const __m256d radius = _mm256_blendv_pd(
        _mm256_set1_pd(-1.0), _mm256_maskload_pd(s.radius + k, lanes), _mm256_castsi256_pd(lanes));
    bits |= spheres_within_reach_x4(
                pv,
                {_mm256_maskload_pd(s.x + k, lanes), _mm256_maskload_pd(s.y + k, lanes),
                 _mm256_maskload_pd(s.z + k, lanes)},
                radius, r)
            << k;
  }
  return bits;
}

// The AVX-512 forms: the AVX2 forms' operations, eight lanes at once, with mask registers for
// the lanes' choices. (GCC 12's avx512fintrin.h fills unused operands with a self-initialised
// _mm512_undefined_pd, which its own -Wuninitialized reports.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
struct V8 {
  __m512d x, y, z;
};

GVKIT_TARGET_AVX512 inline V8 sub8(const V8& a, const V8& b) {
  return {_mm512_sub_pd(a.x, b.x), _mm512_sub_pd(a.y, b.y), _mm512_sub_pd(a.z, b.z)};
}
GVKIT_TARGET_AVX512 inline V8 add8(const V8& a, const V8& b) {
  return {_mm512_add_pd(a.x, b.x), _mm512_add_pd(a.y, b.y), _mm512_add_pd(a.z, b.z)};
}
GVKIT_TARGET_AVX512 inline V8 scale8(const V8& a, __m512d s) {
  return {_mm512_mul_pd(a.x, s), _mm512_mul_pd(a.y, s), _mm512_mul_pd(a.z, s)};
}
GVKIT_TARGET_AVX512 inline __m512d dot8(const V8& a, const V8& b) {
  __m512d s = _mm512_add_pd(_mm512_setzero_pd(), _mm512_mul_pd(a.x, b.x));
  s = _mm512_add_pd(s, _mm512_mul_pd(a.y, b.y));
  return _mm512_add_pd(s, _mm512_mul_pd(a.z, b.z));
}
GVKIT_TARGET_AVX512 inline __mmask8 le0_8(__m512d a) {
  return _mm512_cmp_pd_mask(a, _mm512_setzero_pd(), _CMP_LE_OQ);
}
GVKIT_TARGET_AVX512 inline __mmask8 ge0_8(__m512d a) {
  return _mm512_cmp_pd_mask(a, _mm512_setzero_pd(), _CMP_GE_OQ);
}
// b where the mask is set, else a (blendv's order).
GVKIT_TARGET_AVX512 inline V8 blend8(const V8& a, const V8& b, __mmask8 mask) {
  return {_mm512_mask_blend_pd(mask, a.x, b.x), _mm512_mask_blend_pd(mask, a.y, b.y),
          _mm512_mask_blend_pd(mask, a.z, b.z)};
}
GVKIT_TARGET_AVX512 inline V8 gather8(const VertexArrays& v, const int32_t* i) {
  return {_mm512_setr_pd(v.x[i[0]], v.x[i[1]], v.x[i[2]], v.x[i[3]], v.x[i[4]], v.x[i[5]],
                         v.x[i[6]], v.x[i[7]]),
          _mm512_setr_pd(v.y[i[0]], v.y[i[1]], v.y[i[2]], v.y[i[3]], v.y[i[4]], v.y[i[5]],
                         v.y[i[6]], v.y[i[7]]),
          _mm512_setr_pd(v.z[i[0]], v.z[i[1]], v.z[i[2]], v.z[i[3]], v.z[i[4]], v.z[i[5]],
                         v.z[i[6]], v.z[i[7]])};
}

// point_triangle_distance2_x4 on eight lanes.
GVKIT_TARGET_AVX512 inline __m512d point_triangle_distance2_x8(const V8& p, const V8& a,
                                                               const V8& b, const V8& c) {
  const V8 ab = sub8(b, a), ac = sub8(c, a), ap = sub8(p, a);
  const __m512d d1 = dot8(ab, ap), d2 = dot8(ac, ap);
  const V8 bp = sub8(p, b);
  const __m512d d3 = dot8(ab, bp), d4 = dot8(ac, bp);
  const __m512d vc = _mm512_sub_pd(_mm512_mul_pd(d1, d4), _mm512_mul_pd(d3, d2));
  const V8 cp = sub8(p, c);
  const __m512d d5 = dot8(ab, cp), d6 = dot8(ac, cp);
  const __m512d vb = _mm512_sub_pd(_mm512_mul_pd(d5, d2), _mm512_mul_pd(d1, d6));
  const __m512d va = _mm512_sub_pd(_mm512_mul_pd(d3, d6), _mm512_mul_pd(d5, d4));
  const __m512d d43 = _mm512_sub_pd(d4, d3), d56 = _mm512_sub_pd(d5, d6);

  const __mmask8 in_a = le0_8(d1) & le0_8(d2);
  const __mmask8 in_b = ge0_8(d3) & _mm512_cmp_pd_mask(d4, d3, _CMP_LE_OQ);
  const __mmask8 in_ab = le0_8(vc) & ge0_8(d1) & le0_8(d3);
  const __mmask8 in_c = ge0_8(d6) & _mm512_cmp_pd_mask(d5, d6, _CMP_LE_OQ);
  const __mmask8 in_ac = le0_8(vb) & ge0_8(d2) & le0_8(d6);
  const __mmask8 in_bc = le0_8(va) & ge0_8(d43) & ge0_8(d56);

  // The scalar code's tests in reverse order, so that the first one that holds wins.
  const __m512d zero = _mm512_setzero_pd();
  __m512d num = _mm512_set1_pd(1.0);
  __m512d den = _mm512_add_pd(_mm512_add_pd(va, vb), vc);
  V8 base = a, dir = ab;
  num = _mm512_mask_blend_pd(in_bc, num, d43);
  den = _mm512_mask_blend_pd(in_bc, den, _mm512_add_pd(d43, d56));
  base = blend8(base, b, in_bc);
  dir = blend8(dir, sub8(c, b), in_bc);
  num = _mm512_mask_blend_pd(in_ac, num, d2);
  den = _mm512_mask_blend_pd(in_ac, den, _mm512_sub_pd(d2, d6));
  base = blend8(base, a, in_ac);
  dir = blend8(dir, ac, in_ac);
  __m512d vertex = _mm512_mask_blend_pd(in_c, zero, dot8(cp, cp));
  __mmask8 at_vertex = in_c;
  num = _mm512_mask_blend_pd(in_ab, num, d1);
  den = _mm512_mask_blend_pd(in_ab, den, _mm512_sub_pd(d1, d3));
  base = blend8(base, a, in_ab);
  dir = blend8(dir, ab, in_ab);
  at_vertex = static_cast<__mmask8>(at_vertex & ~in_ab);
  vertex = _mm512_mask_blend_pd(in_b, vertex, dot8(bp, bp));
  at_vertex |= in_b;
  vertex = _mm512_mask_blend_pd(in_a, vertex, dot8(ap, ap));
  at_vertex |= in_a;
  const __mmask8 interior = static_cast<__mmask8>(~(in_bc | in_ac | in_ab | at_vertex));

  const __m512d r = _mm512_div_pd(num, den);
  const __m512d t = _mm512_mask_blend_pd(interior, r, _mm512_mul_pd(vb, r));
  const V8 q = add8(add8(base, scale8(dir, t)),
                    blend8({zero, zero, zero}, scale8(ac, _mm512_mul_pd(vc, r)), interior));
  const V8 pq = sub8(p, q);
  const __m512d on_triangle = dot8(pq, pq);
  // Interior lanes whose 1 / (va + vb + vc) is not finite: a degenerate triangle, the nearest of
  // its corners.
  const __mmask8 degenerate = static_cast<__mmask8>(
      interior & ~_mm512_cmp_pd_mask(_mm512_abs_pd(r), _mm512_set1_pd(HUGE_VAL), _CMP_LT_OQ));
  const __m512d corners = _mm512_min_pd(_mm512_min_pd(dot8(ap, ap), dot8(bp, bp)), dot8(cp, cp));
  const __m512d result = _mm512_mask_blend_pd(degenerate, on_triangle, corners);
  return _mm512_mask_blend_pd(at_vertex, result, vertex);
}

GVKIT_TARGET_AVX512 double nearest_triangle_distance2_avx512(const cv::Vec3d& p,
                                                             const VertexArrays& v,
                                                             const TriangleIndices& t, int n,
                                                             double bound) {
  const V8 pv{_mm512_set1_pd(p[0]), _mm512_set1_pd(p[1]), _mm512_set1_pd(p[2])};
  __m512d best = _mm512_set1_pd(bound);
  int k = 0;
  for (; k + 8 <= n; k += 8) {
    const __m512d d2 = point_triangle_distance2_x8(pv, gather8(v, t.a + k), gather8(v, t.b + k),
                                                   gather8(v, t.c + k));
    // min_pd(d2, best): "d2 < best ? d2 : best", as in the scalar code (a NaN is never taken).
    best = _mm512_min_pd(d2, best);
  }
  if (k < n) {
    // The last 1-7 triangles: lanes past n load index 0 and their distance is not taken.
    int32_t ia[8] = {}, ib[8] = {}, ic[8] = {};
    for (int lane = 0; k + lane < n; ++lane) {
      ia[lane] = t.a[k + lane];
      ib[lane] = t.b[k + lane];
      ic[lane] = t.c[k + lane];
    }
    const __m512d d2 =
        point_triangle_distance2_x8(pv, gather8(v, ia), gather8(v, ib), gather8(v, ic));
    const __mmask8 lanes = static_cast<__mmask8>((1u << (n - k)) - 1);
    best = _mm512_mask_min_pd(best, lanes, d2, best);
  }
  const __m256d h = _mm256_min_pd(_mm512_castpd512_pd256(best), _mm512_extractf64x4_pd(best, 1));
  const __m128d m = _mm_min_pd(_mm256_castpd256_pd128(h), _mm256_extractf128_pd(h, 1));
  return _mm_cvtsd_f64(_mm_min_sd(m, _mm_unpackhi_pd(m, m)));
}

GVKIT_TARGET_AVX512 uint32_t spheres_within_reach_avx512(const cv::Vec3d& p, const SphereArrays& s,
                                                         int n, double reach) {
  const __m512d px = _mm512_set1_pd(p[0]), py = _mm512_set1_pd(p[1]), pz = _mm512_set1_pd(p[2]);
  const __m512d r = _mm512_set1_pd(reach);
  uint32_t bits = 0;
  for (int k = 0; k < n; k += 8) {
    // Lanes past n read nothing and count as empty (radius -1).
    const __mmask8 lanes = n - k >= 8 ? __mmask8{0xff} : static_cast<__mmask8>((1u << (n - k)) - 1);
    const __m512d radius = _mm512_mask_loadu_pd(_mm512_set1_pd(-1.0), lanes, s.radius + k);
    const V8 pq = sub8(
        {px, py, pz}, {_mm512_maskz_loadu_pd(lanes, s.x + k), _mm512_maskz_loadu_pd(lanes, s.y + k),
                       _mm512_maskz_loadu_pd(lanes, s.z + k)});
    const __m512d d2 = dot8(pq, pq);
    const __m512d limit = _mm512_add_pd(radius, r);
    const __mmask8 within =
        ge0_8(radius) & _mm512_cmp_pd_mask(d2, _mm512_mul_pd(limit, limit), _CMP_LT_OQ);
    bits |= static_cast<uint32_t>(within) << k;
  }
  return bits;
}
#pragma GCC diagnostic pop

}  // namespace
#endif

uint32_t spheres_within_reach(const cv::Vec3d& p, const SphereArrays& s, int n, double reach) {
#if defined(GVKIT_X86_SIMD)
  if (gvkit::detail::cpu_has_avx512()) return spheres_within_reach_avx512(p, s, n, reach);
  if (gvkit::detail::cpu_has_avx2()) return spheres_within_reach_avx2(p, s, n, reach);
#endif
  return spheres_within_reach_reference(p, s, n, reach);
}

double nearest_triangle_distance2(const cv::Vec3d& p, const VertexArrays& v,
                                  const TriangleIndices& t, int n, double bound) {
#if defined(GVKIT_X86_SIMD)
  if (gvkit::detail::cpu_has_avx512()) return nearest_triangle_distance2_avx512(p, v, t, n, bound);
  if (gvkit::detail::cpu_has_avx2()) return nearest_triangle_distance2_avx2(p, v, t, n, bound);
#endif
  return nearest_triangle_distance2_reference(p, v, t, n, bound);
}

}  // namespace gvkit::codec
