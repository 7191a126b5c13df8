#pragma once
// Run-time choice of SIMD kernels. The libraries are built for the x86-64 baseline (SSE2, no -m
// flags); a kernel with an AVX2 version compiles it with GVKIT_TARGET_AVX2 (GVKIT_TARGET_AVX2_FMA
// where it also fuses multiply-adds) and calls it when cpu_has_avx2() says the processor has it.
// Every such kernel keeps a plain *_reference version that its tests compare it with on random
// input (tests/codec/*_kernels_test.cpp, tests/facemap/block_matching_test.cpp).

#if defined(__GNUC__) && defined(__x86_64__)
#define GVKIT_X86_SIMD 1
#include <immintrin.h>
#define GVKIT_TARGET_AVX2 __attribute__((target("avx2")))
#define GVKIT_TARGET_AVX2_FMA __attribute__((target("avx2,fma")))
#endif

namespace gvkit::detail {

#if defined(GVKIT_X86_SIMD)
// True when the processor has AVX2 and FMA (every AVX2 processor made has both).
inline bool cpu_has_avx2() {
  static const bool yes = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return yes;
}
#else
inline bool cpu_has_avx2() { return false; }
#endif

}  // namespace gvkit::detail
