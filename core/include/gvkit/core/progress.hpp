#pragma once
// Progress of long work, shown on stderr: a live bar redrawn in place when stderr is a terminal,
// plain lines every few seconds otherwise (logs, CI). Thread-safe: workers call advance().

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace gvkit {

class Progress {
 public:
  // total = number of steps (0 = unknown). enabled = false makes it silent.
  Progress(std::string label, int64_t total, bool enabled = true);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(int64_t steps = 1);
  // Ends the bar with a final line "<label>: N/N in T s".
  void finish();
  int64_t done() const { return done_.load(); }

 private:
  void draw(bool final_line);

  std::string label_;
  int64_t total_;
  bool enabled_, tty_, finished_ = false;
  std::atomic<int64_t> done_{0};
  std::chrono::steady_clock::time_point start_, last_draw_;
  std::mutex mutex_;
};

}  // namespace gvkit
