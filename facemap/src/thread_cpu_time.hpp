#pragma once
// CPU time of the calling thread (ms), for the step timers of the map stage: on a shared machine
// a step's wall time also counts the other processes' turns.

#include <ctime>

namespace gvkit::facemap {

inline double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

}  // namespace gvkit::facemap
