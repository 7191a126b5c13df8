#pragma once
// Real-time pacing for replayed and generated streams: frame i is due at start + i / fps.

#include <chrono>
#include <cstdint>
#include <optional>
#include <thread>

namespace gvkit::detail {

class Pacer {
 public:
  explicit Pacer(double fps) : fps_(fps) {}
  // Sleeps until frame index is due (no-op when fps <= 0). The clock starts at the first call.
  void wait_for(int64_t index) {
    if (fps_ <= 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (!start_) start_ = now - period() * index;
    const auto due = *start_ + period() * index;
    if (due > now) std::this_thread::sleep_until(due);
  }
  // Moves every later due time back by d (the clock pauses, e.g. while a simulation catches up).
  void pause_for(std::chrono::steady_clock::duration d) {
    if (start_) *start_ += d;
  }
  // The index whose time slot [start + i / fps, start + (i + 1) / fps) holds now; nullopt before
  // the first wait_for or when unpaced.
  std::optional<int64_t> index_now() const {
    if (fps_ <= 0 || !start_) return std::nullopt;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - *start_).count();
    return static_cast<int64_t>(elapsed * fps_);
  }

 private:
  std::chrono::steady_clock::duration period() const {
    return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(1.0 / fps_));
  }
  double fps_;
  std::optional<std::chrono::steady_clock::time_point> start_;
};

}  // namespace gvkit::detail
