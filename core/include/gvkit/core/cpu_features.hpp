#pragma once
// Run-time choice of SIMD kernels. The libraries are built for the x86-64 baseline (SSE2, no -m
// flags); a kernel with an AVX2 version compiles it with GVKIT_TARGET_AVX2 (GVKIT_TARGET_AVX2_FMA
// where it also fuses multiply-adds) and calls it when cpu_has_avx2() says the processor has it;
// likewise an AVX-512 version (GVKIT_TARGET_AVX512: the foundation instructions, which bring
// FMA with them in GCC: a file whose kernels must not fuse multiply-adds is compiled with
// -ffp-contract=off) when cpu_has_avx512() does.
// Every such kernel keeps a plain *_reference version that its tests compare it with on random
// input (tests/codec/*_kernels_test.cpp, tests/facemap/block_matching_test.cpp).

#include <cstdlib>
#include <cstring>

#if defined(__GNUC__) && defined(__x86_64__)
#define GVKIT_X86_SIMD 1
#include <immintrin.h>
#define GVKIT_TARGET_AVX2 __attribute__((target("avx2")))
#define GVKIT_TARGET_AVX2_FMA __attribute__((target("avx2,fma")))
#define GVKIT_TARGET_AVX512 __attribute__((target("avx512f")))
#endif

namespace gvkit::detail {

#if defined(GVKIT_X86_SIMD)
// The widest kernels allowed by the environment variable GVKIT_SIMD ("avx512", the default;
// "avx2"; "none": neither, only the x86-64 baseline's code; any other value: the default), so
// that a run can pin a narrower path, for comparison and for the tests of the narrower kernels.
// Read once.
inline int simd_allowed() {
  static const int level = [] {
    const char* v = std::getenv("GVKIT_SIMD");
    if (!v) return 2;
    if (std::strcmp(v, "none") == 0) return 0;
    if (std::strcmp(v, "avx2") == 0) return 1;
    return 2;
  }();
  return level;
}
// True when the processor has AVX2 and FMA (every AVX2 processor made has both) and GVKIT_SIMD
// allows them.
inline bool cpu_has_avx2() {
  static const bool yes =
      simd_allowed() >= 1 && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return yes;
}
// True when the processor (and the system, which saves the registers) has AVX-512 F and AVX2,
// and GVKIT_SIMD allows them.
inline bool cpu_has_avx512() {
  static const bool yes =
      simd_allowed() >= 2 && cpu_has_avx2() && __builtin_cpu_supports("avx512f");
  return yes;
}
#else
inline bool cpu_has_avx2() { return false; }
inline bool cpu_has_avx512() { return false; }
#endif

}  // namespace gvkit::detail
