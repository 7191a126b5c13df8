#include "gvkit/codec/transform.hpp"

#include <cmath>
#include <cstdlib>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace gvkit::codec {
namespace {

// Quantization multipliers and dequantization scales by qp % 6 and position class.
constexpr int32_t kMf4[6][3] = {{13107, 5243, 8066}, {11916, 4660, 7490}, {10082, 4194, 6554},
                                {9362, 3647, 5825},  {8192, 3355, 5243},  {7282, 2893, 4559}};
constexpr int32_t kV4[6][3] = {{10, 16, 13}, {11, 18, 14}, {13, 20, 16},
                               {14, 23, 18}, {16, 25, 20}, {18, 29, 23}};
constexpr int32_t kMf8[6][6] = {
    {13107, 11428, 20972, 12222, 16777, 15481}, {11916, 10826, 19174, 11058, 14980, 14290},
    {10082, 8943, 15978, 9675, 12710, 11985},   {9362, 8228, 14913, 8931, 11984, 11259},
    {8192, 7346, 13159, 7740, 10486, 9777},     {7282, 6428, 11570, 6830, 9118, 8640}};
constexpr int32_t kV8[6][6] = {{20, 18, 32, 19, 25, 24}, {22, 19, 35, 21, 28, 26},
                               {26, 23, 42, 24, 33, 31}, {28, 25, 45, 26, 35, 33},
                               {32, 28, 51, 30, 40, 38}, {36, 32, 58, 34, 46, 43}};

int class4(int i, int j) {
  if (i % 2 == 0 && j % 2 == 0) return 0;
  if (i % 2 == 1 && j % 2 == 1) return 1;
  return 2;
}

int class8(int i, int j) {
  if (i % 4 == 0 && j % 4 == 0) return 0;
  if (i % 2 == 1 && j % 2 == 1) return 1;
  if (i % 4 == 2 && j % 4 == 2) return 2;
  if ((i % 4 == 0 && j % 2 == 1) || (i % 2 == 1 && j % 4 == 0)) return 3;
  if ((i % 4 == 0 && j % 4 == 2) || (i % 4 == 2 && j % 4 == 0)) return 4;
  return 5;
}

template <typename T>
void dct8_1d(T* d, int stride) {
  const T d0 = d[0], d1 = d[stride], d2 = d[2 * stride], d3 = d[3 * stride];
  const T d4 = d[4 * stride], d5 = d[5 * stride], d6 = d[6 * stride], d7 = d[7 * stride];
  const T s07 = d0 + d7, s16 = d1 + d6, s25 = d2 + d5, s34 = d3 + d4;
  const T a0 = s07 + s34, a1 = s16 + s25, a2 = s07 - s34, a3 = s16 - s25;
  const T t07 = d0 - d7, t16 = d1 - d6, t25 = d2 - d5, t34 = d3 - d4;
  const T a4 = t16 + t25 + (t07 + (t07 >> 1));
  const T a5 = t07 - t34 - (t25 + (t25 >> 1));
  const T a6 = t07 + t34 - (t16 + (t16 >> 1));
  const T a7 = t16 - t25 + (t34 + (t34 >> 1));
  d[0] = a0 + a1;
  d[stride] = a4 + (a7 >> 2);
  d[2 * stride] = a2 + (a3 >> 1);
  d[3 * stride] = a5 + (a6 >> 2);
  d[4 * stride] = a0 - a1;
  d[5 * stride] = a6 - (a5 >> 2);
  d[6 * stride] = (a2 >> 1) - a3;
  d[7 * stride] = (a4 >> 2) - a7;
}

void idct8_1d(int64_t* d, int stride) {
  const int64_t d0 = d[0], d1 = d[stride], d2 = d[2 * stride], d3 = d[3 * stride];
  const int64_t d4 = d[4 * stride], d5 = d[5 * stride], d6 = d[6 * stride], d7 = d[7 * stride];
  const int64_t a0 = d0 + d4, a4 = d0 - d4, a2 = (d2 >> 1) - d6, a6 = d2 + (d6 >> 1);
  const int64_t b0 = a0 + a6, b2 = a4 + a2, b4 = a4 - a2, b6 = a0 - a6;
  const int64_t a1 = -d3 + d5 - d7 - (d7 >> 1);
  const int64_t a3 = d1 + d7 - d3 - (d3 >> 1);
  const int64_t a5 = -d1 + d7 + d5 + (d5 >> 1);
  const int64_t a7 = d3 + d5 + d1 + (d1 >> 1);
  const int64_t b1 = a1 + (a7 >> 2), b7 = a7 - (a1 >> 2);
  const int64_t b3 = a3 + (a5 >> 2), b5 = (a3 >> 2) - a5;
  d[0] = b0 + b7;
  d[stride] = b2 + b5;
  d[2 * stride] = b4 + b3;
  d[3 * stride] = b6 + b1;
  d[4 * stride] = b6 - b1;
  d[5 * stride] = b4 - b3;
  d[6 * stride] = b2 - b5;
  d[7 * stride] = b0 - b7;
}

}  // namespace

const uint8_t kZigzag4x4[16] = {0, 1, 4, 8, 5, 2, 3, 6, 9, 12, 13, 10, 7, 11, 14, 15};
const uint8_t kZigzag8x8[64] = {0,  1,  8,  16, 9,  2,  3,  10, 17, 24, 32, 25, 18, 11, 4,  5,
                                12, 19, 26, 33, 40, 48, 41, 34, 27, 20, 13, 6,  7,  14, 21, 28,
                                35, 42, 49, 56, 57, 50, 43, 36, 29, 22, 15, 23, 30, 37, 44, 51,
                                58, 59, 52, 45, 38, 31, 39, 46, 53, 60, 61, 54, 47, 55, 62, 63};

void forward_transform4x4(const int32_t* r, int32_t* c) {
  int32_t t[16];
  for (int i = 0; i < 4; ++i) {
    const int32_t* s = r + 4 * i;
    const int32_t p0 = s[0] + s[3], p1 = s[1] + s[2], m0 = s[0] - s[3], m1 = s[1] - s[2];
    t[4 * i + 0] = p0 + p1;
    t[4 * i + 1] = 2 * m0 + m1;
    t[4 * i + 2] = p0 - p1;
    t[4 * i + 3] = m0 - 2 * m1;
  }
  for (int j = 0; j < 4; ++j) {
    const int32_t p0 = t[j] + t[12 + j], p1 = t[4 + j] + t[8 + j];
    const int32_t m0 = t[j] - t[12 + j], m1 = t[4 + j] - t[8 + j];
    c[j] = p0 + p1;
    c[4 + j] = 2 * m0 + m1;
    c[8 + j] = p0 - p1;
    c[12 + j] = m0 - 2 * m1;
  }
}

void inverse_transform4x4(const int64_t* c, int32_t* r) {
  int64_t t[16];
  for (int i = 0; i < 4; ++i) {
    const int64_t* s = c + 4 * i;
    const int64_t e = s[0] + s[2], f = s[0] - s[2];
    const int64_t g = (s[1] >> 1) - s[3], h = s[1] + (s[3] >> 1);
    t[4 * i + 0] = e + h;
    t[4 * i + 1] = f + g;
    t[4 * i + 2] = f - g;
    t[4 * i + 3] = e - h;
  }
  for (int j = 0; j < 4; ++j) {
    const int64_t e = t[j] + t[8 + j], f = t[j] - t[8 + j];
    const int64_t g = (t[4 + j] >> 1) - t[12 + j], h = t[4 + j] + (t[12 + j] >> 1);
    r[j] = static_cast<int32_t>((e + h + 32) >> 6);
    r[4 + j] = static_cast<int32_t>((f + g + 32) >> 6);
    r[8 + j] = static_cast<int32_t>((f - g + 32) >> 6);
    r[12 + j] = static_cast<int32_t>((e - h + 32) >> 6);
  }
}

void forward_transform8x8(const int32_t* r, int32_t* c) {
  for (int i = 0; i < 64; ++i) c[i] = r[i];
  for (int i = 0; i < 8; ++i) dct8_1d(c + 8 * i, 1);
  for (int j = 0; j < 8; ++j) dct8_1d(c + j, 8);
}

void inverse_transform8x8(const int64_t* c, int32_t* r) {
  int64_t t[64];
  for (int i = 0; i < 64; ++i) t[i] = c[i];
  for (int i = 0; i < 8; ++i) idct8_1d(t + 8 * i, 1);
  for (int j = 0; j < 8; ++j) idct8_1d(t + j, 8);
  for (int i = 0; i < 64; ++i) r[i] = static_cast<int32_t>((t[i] + 32) >> 6);
}

namespace {

// Multipliers and scales per position of the block, by qp % 6 (class4 / class8 unrolled).
struct QuantTables {
  int32_t mf4[6][16], v4[6][16], mf8[6][64], v8[6][64];
  QuantTables() {
    for (int rem = 0; rem < 6; ++rem) {
      for (int k = 0; k < 16; ++k) {
        mf4[rem][k] = kMf4[rem][class4(k / 4, k % 4)];
        v4[rem][k] = kV4[rem][class4(k / 4, k % 4)];
      }
      for (int k = 0; k < 64; ++k) {
        mf8[rem][k] = kMf8[rem][class8(k / 8, k % 8)];
        v8[rem][k] = kV8[rem][class8(k / 8, k % 8)];
      }
    }
  }
};

const QuantTables& quant_tables() {
  static const QuantTables tables;
  return tables;
}

// Quantization with the rounding offset 2^qbits / rounding_divisor (3: intra, 6: the inter dead
// zone).
void quantize_with_rounding(int n, const int32_t* coeffs, int qp, int rounding_divisor,
                            int32_t* levels) {
  const int per = qp / 6, rem = qp % 6;
  const int qbits = (n == 4 ? 15 : 16) + per;
  const int64_t f = (int64_t{1} << qbits) / rounding_divisor;
  const int32_t* mf = n == 4 ? quant_tables().mf4[rem] : quant_tables().mf8[rem];
  int k = 0;
#if defined(__SSE2__)
  // Four at a time: |w| (< 2^23) times mf (< 2^15) as unsigned 32 x 32 -> 64-bit products of
  // the even and the odd lanes, + f, >> qbits (the quotient < 2^32), the sign put back.
  const __m128i fv = _mm_set1_epi64x(f), shift = _mm_cvtsi32_si128(qbits);
  for (; k + 4 <= n * n; k += 4) {
    const __m128i w = _mm_loadu_si128(reinterpret_cast<const __m128i*>(coeffs + k));
    const __m128i sign = _mm_srai_epi32(w, 31);
    const __m128i a = _mm_sub_epi32(_mm_xor_si128(w, sign), sign);
    const __m128i m = _mm_loadu_si128(reinterpret_cast<const __m128i*>(mf + k));
    const __m128i even = _mm_srl_epi64(_mm_add_epi64(_mm_mul_epu32(a, m), fv), shift);
    const __m128i odd = _mm_srl_epi64(
        _mm_add_epi64(_mm_mul_epu32(_mm_srli_epi64(a, 32), _mm_srli_epi64(m, 32)), fv), shift);
    const __m128i z = _mm_or_si128(even, _mm_slli_epi64(odd, 32));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(levels + k),
                     _mm_sub_epi32(_mm_xor_si128(z, sign), sign));
  }
#endif
  for (; k < n * n; ++k) {
    const int64_t w = coeffs[k];
    const int64_t z = ((w < 0 ? -w : w) * mf[k] + f) >> qbits;
    levels[k] = static_cast<int32_t>(w < 0 ? -z : z);
  }
}

}  // namespace

void quantize_reference(int n, const int32_t* coeffs, int qp, int32_t* levels) {
  const int per = qp / 6, rem = qp % 6;
  const int qbits = (n == 4 ? 15 : 16) + per;
  const int64_t f = (int64_t{1} << qbits) / 3;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int k = i * n + j;
      const int64_t mf = n == 4 ? kMf4[rem][class4(i, j)] : kMf8[rem][class8(i, j)];
      const int64_t w = coeffs[k];
      const int64_t z = (std::llabs(w) * mf + f) >> qbits;
      levels[k] = static_cast<int32_t>(w < 0 ? -z : z);
    }
}

void quantize(int n, const int32_t* coeffs, int qp, int32_t* levels) {
  quantize_with_rounding(n, coeffs, qp, 3, levels);
}

void quantize_inter(int n, const int32_t* coeffs, int qp, int32_t* levels) {
  quantize_with_rounding(n, coeffs, qp, 6, levels);
}

namespace {

// absolute_products with factors[k], or with `factor` everywhere when factors is null.
void absolute_products_of(const int32_t* values, const int32_t* factors, int32_t factor, int count,
                          int64_t* out) {
  int k = 0;
#if defined(__SSE2__)
  // |v| as unsigned 32 bits (INT32_MIN: 2^31), the even and the odd lanes' unsigned 32 x 32 ->
  // 64-bit products, put back in order.
  const __m128i one_factor = _mm_set1_epi32(factor);
  for (; k + 4 <= count; k += 4) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(values + k));
    const __m128i sign = _mm_srai_epi32(v, 31);
    const __m128i a = _mm_sub_epi32(_mm_xor_si128(v, sign), sign);
    const __m128i m =
        factors ? _mm_loadu_si128(reinterpret_cast<const __m128i*>(factors + k)) : one_factor;
    const __m128i even = _mm_mul_epu32(a, m);
    const __m128i odd = _mm_mul_epu32(_mm_srli_epi64(a, 32), _mm_srli_epi64(m, 32));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + k), _mm_unpacklo_epi64(even, odd));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + k + 2), _mm_unpackhi_epi64(even, odd));
  }
#endif
  for (; k < count; ++k) out[k] = std::llabs(int64_t{values[k]}) * (factors ? factors[k] : factor);
}

}  // namespace

void absolute_products(const int32_t* values, const int32_t* factors, int count, int64_t* out) {
  absolute_products_of(values, factors, 0, count, out);
}

void absolute_products(const int32_t* values, int32_t factor, int count, int64_t* out) {
  absolute_products_of(values, nullptr, factor, count, out);
}

int quantization_numerators(int n, const int32_t* coeffs, int qp, int64_t* numer) {
  const int32_t* mf = n == 4 ? quant_tables().mf4[qp % 6] : quant_tables().mf8[qp % 6];
  absolute_products(coeffs, mf, n * n, numer);
  return (n == 4 ? 15 : 16) + qp / 6;
}

void dequantize_reference(int n, const int32_t* levels, int qp, int64_t* coeffs) {
  const int per = qp / 6, rem = qp % 6;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int k = i * n + j;
      if (n == 4) {
        coeffs[k] =
            (static_cast<int64_t>(levels[k]) * kV4[rem][class4(i, j)]) * (int64_t{1} << per);
      } else {
        const int64_t scaled =
            static_cast<int64_t>(levels[k]) * 16 * kV8[rem][class8(i, j)] * (int64_t{1} << per);
        coeffs[k] = (scaled + 32) >> 6;
      }
    }
}

void dequantize(int n, const int32_t* levels, int qp, int64_t* coeffs) {
  const int per = qp / 6, rem = qp % 6;
  const int64_t scale = int64_t{1} << per;
  if (n == 4) {
    const int32_t* v = quant_tables().v4[rem];
    for (int k = 0; k < 16; ++k) coeffs[k] = static_cast<int64_t>(levels[k]) * v[k] * scale;
    return;
  }
  const int32_t* v = quant_tables().v8[rem];
  for (int k = 0; k < 64; ++k)
    coeffs[k] = (static_cast<int64_t>(levels[k]) * 16 * v[k] * scale + 32) >> 6;
}

const int32_t* dequantization_factors8x8(int qp) { return quant_tables().v8[qp % 6]; }
const int32_t* dequantization_factors4x4(int qp) { return quant_tables().v4[qp % 6]; }

double quantizer_step(int qp) { return 0.625 * std::pow(2.0, qp / 6.0); }

int64_t satd4x4(const int32_t* d, int stride) {
  // |d| < 2^17, so every Hadamard sum stays below 2^21: 32-bit arithmetic is exact.
  int32_t t[16];
  for (int i = 0; i < 4; ++i) {
    const int32_t* s = d + i * stride;
    const int32_t a0 = s[0] + s[1], a1 = s[0] - s[1], a2 = s[2] + s[3], a3 = s[2] - s[3];
    t[4 * i + 0] = a0 + a2;
    t[4 * i + 1] = a1 + a3;
    t[4 * i + 2] = a0 - a2;
    t[4 * i + 3] = a1 - a3;
  }
  int32_t sum = 0;
  for (int j = 0; j < 4; ++j) {
    const int32_t a0 = t[j] + t[4 + j], a1 = t[j] - t[4 + j];
    const int32_t a2 = t[8 + j] + t[12 + j], a3 = t[8 + j] - t[12 + j];
    sum += std::abs(a0 + a2) + std::abs(a1 + a3) + std::abs(a0 - a2) + std::abs(a1 - a3);
  }
  return sum / 2;
}

}  // namespace gvkit::codec
