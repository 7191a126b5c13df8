// The quadratic 16x16 intra mode (format 1.13, docs/bitstream.md 6.1): a least-squares quadratic
// surface through the two rows above and the two columns left of the macroblock, evaluated over
// the block in integer arithmetic.
#include "gvkit/codec/quadratic_intra.hpp"

#include <algorithm>
#include <cstdint>

#include "gvkit/core/cpu_features.hpp"

namespace gvkit::codec {
namespace {

// kQuadraticFit[j][k] = round(2^24 (A^T A)^-1 A^T)[j][k]: the weight of neighbour k in
// coefficient j of q(x, y) = c0 + c1 x + c2 y + c3 x^2 + c4 y^2 + c5 x y, with A the design
// matrix of the 68 neighbours in kQuadraticNeighbours order (computed in exact rational
// arithmetic, rounded, and the largest weight of each row adjusted so that row 0 sums to 2^24
// and rows 1-5 to 0: a constant neighbourhood predicts itself exactly). Every weight is below
// 2^20 in magnitude, so 32 bits hold it (and the AVX2 fit multiplies 32 x 32 -> 64 bits).
constexpr int32_t kQuadraticFit[6][kQuadraticNeighbours] = {
    // 1
    {876543,  782323,  690761, 601861,  515624,  432049,  351137,  272887,  197299,  124374,
     54111,   -13489,  -78427, -140702, -200315, -257265, -311553, -363179, 782323,  718139,
     656618,  597759,  541562, 488028,  437156,  388947,  343400,  300516,  260294,  222735,
     187838,  155603,  126031, 99121,   74874,   53289,   690761,  601861,  515624,  432049,
     351137,  272887,  197299, 124374,  54111,   -13489,  -78427,  -140702, -200315, -257265,
     -311553, -363179, 656618, 597759,  541562,  488028,  437156,  388947,  343400,  300516,
     260294,  222735,  187838, 155603,  126031,  99121,   74874,   53289},
    // x
    {-421405, -294174, -182268, -85687, -4432,  61498,   112102,  147379,  167332,  171958,
     161259,  135234,  93883,   37206,  -34796, -122124, -224778, -342757, -355260, -221446,
     -102958, 204,     88040,   160551, 217736, 259595,  286129,  297336,  293218,  273775,
     239005,  188910,  123489,  42743,  -53330, -164728, -295614, -242467, -195821, -155675,
     -122028, -94882,  -74236,  -60089, -52443, -51297,  -56650,  -68504,  -86858,  -111711,
     -143065, -180919, -155219, -95491, -42263, 4464,    44692,   78420,   105647,  126375,
     140603,  148330,  149558,  144286, 132513, 114241,  89468,   58196},
    // y
    {-421405, -355260, -295614, -242467, -195821, -155675, -122028, -94882,  -74236,  -60089,
     -52443,  -51297,  -56650,  -68504,  -86858,  -111711, -143065, -180919, -294174, -221446,
     -155219, -95491,  -42263,  4464,    44692,   78420,   105647,  126375,  140603,  148330,
     149558,  144286,  132513,  114241,  89468,   58196,   -182268, -85687,  -4432,   61498,
     112102,  147379,  167332,  171958,  161259,  135234,  93883,   37206,   -34796,  -122124,
     -224778, -342757, -102958, 204,     88040,   160551,  217736,  259595,  286129,  297336,
     293218,  273775,  239005,  188910,  123489,  42743,   -53330,  -164728},
    // x^2
    {29736,  18574,  8815,   459,    -6494,  -12043, -16190, -18933, -20273, -20210, -18743, -15874,
     -11601, -5925,  1154,   9636,   19522,  30811,  24354,  13889,  4827,   -2831,  -9087,  -13939,
     -17388, -19434, -20077, -19316, -17152, -13586, -8615,  -2242,  5534,   14714,  25297,  37280,
     19463,  15065,  11158,  7742,   4819,   2388,   448,    -1000,  -1956,  -2420,  -2393,  -1873,
     -862,   641,    2635,   5122,   9696,   5994,   2785,   67,     -2159,  -3893,  -5136,  -5886,
     -6145,  -5912,  -5187,  -3970,  -2262,  -62,    2630,   5814},
    // y^2
    {29736,  24354,  19463, 15065,  11158,  7742,   4819,   2388,   448,    -1000,  -1956,  -2420,
     -2393,  -1873,  -862,  641,    2635,   5122,   18574,  13889,  9696,   5994,   2785,   67,
     -2159,  -3893,  -5136, -5886,  -6145,  -5912,  -5187,  -3970,  -2262,  -62,    2630,   5814,
     8815,   459,    -6494, -12043, -16190, -18933, -20273, -20210, -18743, -15874, -11601, -5925,
     1154,   9636,   19522, 30811,  4827,   -2831,  -9087,  -13939, -17388, -19434, -20077, -19316,
     -17152, -13586, -8615, -2242,  5534,   14714,  25297,  37280},
    // xy
    {54725,  36499,  19667,  4231,   -9811,  -22459, -33711, -43569, -52033, -59102, -64776, -69055,
     -71940, -73430, -73525, -72226, -69532, -65443, 36499,  29630,  24157,  20078,  17393,  16104,
     16209,  17708,  20603,  24892,  30575,  37653,  46126,  55994,  67256,  79913,  93965,  109412,
     19667,  4231,   -9811,  -22459, -33711, -43569, -52033, -59102, -64776, -69055, -71940, -73430,
     -73525, -72226, -69532, -65443, 24157,  20078,  17393,  16104,  16209,  17708,  20603,  24892,
     30575,  37653,  46126,  55994,  67256,  79913,  93965,  109411}};

static_assert(kQuadraticNeighbours % 4 == 0);  // the AVX2 fit takes four at a time

// c_j = sum_i w_ji s_i in 64 bits (products below 2^36), one 32 x 32 -> 64-bit multiply per lane.
void fit_coefficients(const int32_t* s, int64_t* c) {
  for (int j = 0; j < 6; ++j) {
    c[j] = 0;
    for (int i = 0; i < kQuadraticNeighbours; ++i)
      c[j] += static_cast<int64_t>(kQuadraticFit[j][i]) * s[i];
  }
}
#if defined(GVKIT_X86_SIMD)
GVKIT_TARGET_AVX2 void fit_coefficients_avx2(const int32_t* s, int64_t* c) {
  for (int j = 0; j < 6; ++j) {
    __m256i sum = _mm256_setzero_si256();
    for (int i = 0; i < kQuadraticNeighbours; i += 4) {
      const __m256i sv =
          _mm256_cvtepi32_epi64(_mm_loadu_si128(reinterpret_cast<const __m128i*>(s + i)));
      const __m256i wv = _mm256_cvtepi32_epi64(
          _mm_loadu_si128(reinterpret_cast<const __m128i*>(&kQuadraticFit[j][i])));
      sum = _mm256_add_epi64(sum, _mm256_mul_epi32(sv, wv));
    }
    alignas(32) int64_t lanes[4];
    _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), sum);
    c[j] = lanes[0] + lanes[1] + lanes[2] + lanes[3];  // integers: any order gives the same sum
  }
}
#endif

// The fit of the block at (x0, y0): b, the sample at (x0 - 1, y0 - 1), and the coefficients c_j
// (in units of 2^-24) of q(x, y) fitted to the neighbours minus b; returns b.
int64_t quadratic_fit(const uint16_t* plane, int stride, int x0, int y0, int64_t* c) {
  // Neighbours relative to the corner sample above-left of the block (keeps the sums small).
  const auto at = [&](int x, int y) {
    return static_cast<int32_t>(plane[static_cast<int64_t>(y0 + y) * stride + x0 + x]);
  };
  const int32_t base = at(-1, -1);
  int32_t s[kQuadraticNeighbours];
  int k = 0;
  for (int y = -2; y <= -1; ++y)
    for (int x = -2; x < 16; ++x) s[k++] = at(x, y) - base;
  for (int x = -2; x <= -1; ++x)
    for (int y = 0; y < 16; ++y) s[k++] = at(x, y) - base;
#if defined(GVKIT_X86_SIMD)
  if (gvkit::detail::cpu_has_avx2()) {
    fit_coefficients_avx2(s, c);
    return base;
  }
#endif
  fit_coefficients(s, c);
  return base;
}

int32_t quadratic_sample(int64_t base, int64_t q, int max_value) {
  const int64_t v = base + ((q + (int64_t{1} << 23)) >> 24);
  return static_cast<int32_t>(std::clamp<int64_t>(v, 0, max_value));
}

#if defined(GVKIT_X86_SIMD)
// The rows of predict_quadratic16 from the first row's q and steps, four samples per lane group.
// |q| < 68 x 2^36 x 706 < 2^52 (|c_j| < 68 x 2^36, and the monomials sum to at most 706 over
// the block), so (q + 2^23) >> 24 (arithmetic) is ((q + 2^23 + 2^62) >> 24 (logical)) - 2^38.
GVKIT_TARGET_AVX2 void evaluate_rows_avx2(const int64_t* row0, const int64_t* down0, int64_t step,
                                          int64_t base, int max_value, int32_t* out) {
  __m256i row[4], down[4];
  for (int k = 0; k < 4; ++k) {
    row[k] = _mm256_load_si256(reinterpret_cast<const __m256i*>(row0 + 4 * k));
    down[k] = _mm256_load_si256(reinterpret_cast<const __m256i*>(down0 + 4 * k));
  }
  const __m256i step_v = _mm256_set1_epi64x(step);
  const __m256i bias = _mm256_set1_epi64x((int64_t{1} << 23) + (int64_t{1} << 62));
  const __m256i offset = _mm256_set1_epi64x(base - (int64_t{1} << 38));
  const __m256i zero = _mm256_setzero_si256(), top = _mm256_set1_epi64x(max_value);
  const __m256i pack = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
  for (int y = 0; y < 16; ++y) {
    for (int k = 0; k < 4; k += 2) {
      __m256i v[2];
      for (int h = 0; h < 2; ++h) {
        __m256i a =
            _mm256_add_epi64(_mm256_srli_epi64(_mm256_add_epi64(row[k + h], bias), 24), offset);
        a = _mm256_blendv_epi8(a, zero, _mm256_cmpgt_epi64(zero, a));
        a = _mm256_blendv_epi8(a, top, _mm256_cmpgt_epi64(a, top));
        v[h] = a;
        row[k + h] = _mm256_add_epi64(row[k + h], down[k + h]);
        down[k + h] = _mm256_add_epi64(down[k + h], step_v);
      }
      // The low 32 bits of the eight 64-bit lanes, in order.
      const __m256i lo = _mm256_permutevar8x32_epi32(v[0], pack);
      const __m256i hi = _mm256_permutevar8x32_epi32(v[1], pack);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + y * 16 + 4 * k),
                          _mm256_permute2x128_si256(lo, hi, 0x20));
    }
  }
}
#endif

}  // namespace

void predict_quadratic16_reference(const uint16_t* plane, int stride, int x0, int y0, int max_value,
                                   int32_t* out) {
  int64_t c[6];
  const int64_t base = quadratic_fit(plane, stride, x0, y0, c);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const int64_t q = c[0] + c[1] * x + c[2] * y + c[3] * x * x + c[4] * y * y + c[5] * x * y;
      out[y * 16 + x] = quadratic_sample(base, q, max_value);
    }
}

// With AVX2: q by forward differences, exact in 64-bit integers: along a row q(x + 1, y) -
// q(x, y) = c1 + c3 (2 x + 1) + c5 y, whose own step is 2 c3; from one row to the next
// q(x, y + 1) - q(x, y) = c2 + c4 (2 y + 1) + c5 x, whose step is 2 c4. Without: the definition.
void predict_quadratic16(const uint16_t* plane, int stride, int x0, int y0, int max_value,
                         int32_t* out) {
#if defined(GVKIT_X86_SIMD)
  if (gvkit::detail::cpu_has_avx2()) {
    int64_t c[6];
    const int64_t base = quadratic_fit(plane, stride, x0, y0, c);
    alignas(32) int64_t row[16], down[16];  // q(x, 0), and q(x, 1) - q(x, 0)
    int64_t q = c[0], dx = c[1] + c[3];
    for (int x = 0; x < 16; ++x) {
      row[x] = q;
      down[x] = c[2] + c[4] + c[5] * x;
      q += dx;
      dx += 2 * c[3];
    }
    evaluate_rows_avx2(row, down, 2 * c[4], base, max_value, out);
    return;
  }
#endif
  predict_quadratic16_reference(plane, stride, x0, y0, max_value, out);
}

}  // namespace gvkit::codec
