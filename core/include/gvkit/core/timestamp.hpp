#pragma once
// Capture-clock time: nanoseconds of a monotonic clock (std::chrono::steady_clock for live
// sources, frame_index / fps for synthetic and replayed ones).

#include <chrono>

namespace gvkit {
using Timestamp = std::chrono::nanoseconds;

// Now on the monotonic capture clock.
inline Timestamp monotonic_now() {
  return std::chrono::duration_cast<Timestamp>(std::chrono::steady_clock::now().time_since_epoch());
}
}  // namespace gvkit
