#include "gvkit/codec/reconstruction_store.hpp"

#include "gvkit/core/cpu_features.hpp"

namespace gvkit::codec {

void store_reconstruction_reference(int n, const int32_t* pred, int pred_stride,
                                    const int32_t* residual, int max_value, uint16_t* dst,
                                    ptrdiff_t dst_stride) {
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const int64_t v = int64_t{pred[y * pred_stride + x]} + (residual ? residual[y * n + x] : 0);
      dst[y * dst_stride + x] = static_cast<uint16_t>(v < 0 ? 0 : (v > max_value ? max_value : v));
    }
}

#if defined(GVKIT_X86_SIMD)
namespace {

// Eight sums clipped, where a 32-bit sum overflowed taking the clip of the true (64-bit) sum,
// whose sign is then the sign of pred (the operands had the same sign).
GVKIT_TARGET_AVX2 inline __m256i clipped_sum(__m256i p, __m256i r, __m256i max_value) {
  const __m256i sum = _mm256_add_epi32(p, r);
  const __m256i overflow =
      _mm256_srai_epi32(_mm256_and_si256(_mm256_xor_si256(p, sum), _mm256_xor_si256(r, sum)), 31);
  const __m256i clipped =
      _mm256_min_epi32(_mm256_max_epi32(sum, _mm256_setzero_si256()), max_value);
  const __m256i saturated = _mm256_andnot_si256(_mm256_srai_epi32(p, 31), max_value);
  return _mm256_blendv_epi8(clipped, saturated, overflow);
}

GVKIT_TARGET_AVX2 void store_reconstruction_avx2(int n, const int32_t* pred, int pred_stride,
                                                 const int32_t* residual, int max_value,
                                                 uint16_t* dst, ptrdiff_t dst_stride) {
  const __m256i max_v = _mm256_set1_epi32(max_value), zero = _mm256_setzero_si256();
  if (n == 4) {  // two rows per vector
    for (int y = 0; y < 4; y += 2) {
      const __m256i p = _mm256_setr_m128i(
          _mm_loadu_si128(reinterpret_cast<const __m128i*>(pred + y * pred_stride)),
          _mm_loadu_si128(reinterpret_cast<const __m128i*>(pred + (y + 1) * pred_stride)));
      const __m256i r =
          residual ? _mm256_loadu_si256(reinterpret_cast<const __m256i*>(residual + y * 4)) : zero;
      const __m256i v = clipped_sum(p, r, max_v);
      const __m128i packed =
          _mm_packus_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
      _mm_storel_epi64(reinterpret_cast<__m128i*>(dst + y * dst_stride), packed);
      _mm_storel_epi64(reinterpret_cast<__m128i*>(dst + (y + 1) * dst_stride),
                       _mm_srli_si128(packed, 8));
    }
    return;
  }
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; x += 8) {
      const __m256i p =
          _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pred + y * pred_stride + x));
      const __m256i r =
          residual ? _mm256_loadu_si256(reinterpret_cast<const __m256i*>(residual + y * n + x))
                   : zero;
      const __m256i v = clipped_sum(p, r, max_v);
      const __m128i packed =
          _mm_packus_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + y * dst_stride + x), packed);
    }
}

}  // namespace
#endif

void store_reconstruction(int n, const int32_t* pred, int pred_stride, const int32_t* residual,
                          int max_value, uint16_t* dst, ptrdiff_t dst_stride) {
#if defined(GVKIT_X86_SIMD)
  if (gvkit::detail::cpu_has_avx2())
    return store_reconstruction_avx2(n, pred, pred_stride, residual, max_value, dst, dst_stride);
#endif
  store_reconstruction_reference(n, pred, pred_stride, residual, max_value, dst, dst_stride);
}

}  // namespace gvkit::codec
