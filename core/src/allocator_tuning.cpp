#include "gvkit/core/allocator_tuning.hpp"

#include <cstdlib>  // defines __GLIBC__ on glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace gvkit {

bool tune_allocator_for_frames() {
#if defined(__GLIBC__)
  // Setting the mmap threshold explicitly also turns off glibc's dynamic adjustment of it.
  const bool mmap_ok = mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024) == 1;
  const bool trim_ok = mallopt(M_TRIM_THRESHOLD, 256 * 1024 * 1024) == 1;
  return mmap_ok && trim_ok;
#else
  return false;
#endif
}

}  // namespace gvkit
