#include "gvkit/core/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace gvkit {
namespace {
constexpr auto kTtyInterval = std::chrono::milliseconds(100);
constexpr auto kLineInterval = std::chrono::seconds(5);
}  // namespace

Progress::Progress(std::string label, int64_t total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled),
      tty_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() {
  if (!finished_) finish();
}

void Progress::advance(int64_t steps) {
  done_.fetch_add(steps);
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  if (now - last_draw_ < (tty_ ? kTtyInterval : kLineInterval)) return;
  last_draw_ = now;
  draw(false);
}

void Progress::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (enabled_) draw(true);
}

void Progress::draw(bool final_line) {
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const int64_t done = done_.load();
  char counts[64];
  if (total_ > 0)
    std::snprintf(counts, sizeof counts, "%lld/%lld", static_cast<long long>(done),
                  static_cast<long long>(total_));
  else
    std::snprintf(counts, sizeof counts, "%lld", static_cast<long long>(done));
  if (tty_ && !final_line) {
    constexpr int kWidth = 30;
    const int filled = total_ > 0 ? static_cast<int>(kWidth * done / total_) : 0;
    std::fprintf(stderr, "\r%s [%-*s] %s %.1fs", label_.c_str(), kWidth,
                 std::string(filled, '#').c_str(), counts, seconds);
  } else {
    std::fprintf(stderr, "%s%s: %s in %.1f s\n", tty_ ? "\r\033[K" : "", label_.c_str(), counts,
                 seconds);
  }
  std::fflush(stderr);
}

}  // namespace gvkit
