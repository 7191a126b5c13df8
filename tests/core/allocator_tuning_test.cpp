// Heap settings for frame-by-frame work: large arrays stay on the heap instead of being mapped
// and unmapped (and so page-faulted in again) every frame.
#include "gvkit/core/allocator_tuning.hpp"

#include <cstdlib>
#include <cstring>

#include <gtest/gtest.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace gvkit {
namespace {

#if defined(__SANITIZE_ADDRESS__)
#define GVKIT_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GVKIT_ASAN 1
#endif
#endif

TEST(AllocatorTuning, LargeArraysComeFromTheHeapAfterwards) {
#if defined(GVKIT_ASAN)
  GTEST_SKIP() << "AddressSanitizer replaces the allocator (its mallopt does nothing, and freed "
                  "memory is quarantined)";
#elif defined(__GLIBC__)
  ASSERT_TRUE(tune_allocator_for_frames());
  const size_t before = mallinfo2().hblkhd;  // bytes in mmapped blocks
  const size_t size = 8 * 1024 * 1024;       // a 255K-vertex mesh array is of this order
  char* a = static_cast<char*>(std::malloc(size));
  ASSERT_NE(a, nullptr);
  std::memset(a, 1, size);
  EXPECT_EQ(mallinfo2().hblkhd, before);  // not a mapping of its own
  std::free(a);
  // Freed memory stays in the process: the next array of the same size reuses it.
  char* b = static_cast<char*>(std::malloc(size));
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(mallinfo2().hblkhd, before);
  EXPECT_EQ(b, a);
  std::free(b);
#else
  EXPECT_FALSE(tune_allocator_for_frames());
#endif
}

}  // namespace
}  // namespace gvkit
