#pragma once
// Run-time choice of the codec's SIMD kernels. The library is built for the x86-64 baseline
// (SSE2, no -m flags); a kernel with an AVX2 version compiles it with GVKIT_TARGET_AVX2 and
// calls it when cpu_has_avx2() says the processor has AVX2. Every such kernel keeps a plain
// *_reference version that returns the same values bit for bit (tests/codec/*_kernels_test.cpp
// compare them on random input; bench/codec/codec_decoder_kernels_benchmark times both).

#if defined(__GNUC__) && defined(__x86_64__)
#define GVKIT_X86_SIMD 1
#include <immintrin.h>
#define GVKIT_TARGET_AVX2 __attribute__((target("avx2")))
#endif

namespace gvkit::codec::detail {

#if defined(GVKIT_X86_SIMD)
inline bool cpu_has_avx2() {
  static const bool yes = __builtin_cpu_supports("avx2");
  return yes;
}
#else
inline bool cpu_has_avx2() { return false; }
#endif

}  // namespace gvkit::codec::detail
