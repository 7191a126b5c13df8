#pragma once
// PatternProjector: a fullscreen window on a chosen monitor (the projector is a monitor to the
// system) that shows pattern images one after another and reports when each became visible, for
// software frame <-> pattern sync (pattern_sync.hpp). GLFW + OpenGL; built when
// GVKIT_WITH_PROJECTOR is on.

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/capture/pattern_sync.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/core/timestamp.hpp"

namespace gvkit {

struct PatternProjectorOptions {
  int monitor = 0;         // index among the connected monitors (0 = primary)
  bool fullscreen = true;  // false: a plain window (previews, tests)
  int window_width = 0;    // windowed size in px; 0 = the first pattern's size
  int window_height = 0;
  bool vsync = true;  // swap on the display refresh (pattern changes are frame-aligned)
  Status check() const;
};

// Ok when n_patterns per cycle at cycles_per_second fits the display: every pattern needs at
// least one refresh. Else a Status saying how many patterns per second were asked and the most
// the display shows.
Status check_pattern_rate(int n_patterns, double cycles_per_second, double refresh_hz);

// One PatternProjector at a time per process (it owns GLFW's global state); use it from one thread.
class PatternProjector {
 public:
  // Opens the window. Fails with a clear Status when there is no display (DISPLAY /
  // WAYLAND_DISPLAY unset or unreachable), no such monitor (listing those connected), or no
  // OpenGL context.
  static Result<std::unique_ptr<PatternProjector>> open(const PatternProjectorOptions& options);
  ~PatternProjector();
  PatternProjector(const PatternProjector&) = delete;
  PatternProjector& operator=(const PatternProjector&) = delete;

  // Uploads the patterns: one channel CV_8U (CV_16U is shown at its top 8 bits) or CV_8UC3 BGR,
  // all the same size; each is stretched to the window with nearest sampling (pixel exact when
  // the sizes match). Fails naming the first bad pattern.
  Status set_patterns(const std::vector<cv::Mat>& patterns);
  int pattern_count() const;

  // Shows pattern k and returns the monotonic time it became visible: after the buffer swap and
  // glFinish. Fails when the window was closed.
  Result<Timestamp> show(int k);
  // Shows every pattern once in order, `cycles` times, and returns the presentations (cycle
  // numbers from first_cycle).
  Result<std::vector<PatternPresentation>> run_cycles(int cycles, int64_t first_cycle = 0);

  // "monitor 0 'DP-1' 1920x1080 @ 60 Hz, fullscreen".
  std::string describe() const;
  double refresh_hz() const;
  cv::Size size() const;
  bool close_requested() const;

 private:
  struct Impl;
  explicit PatternProjector(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace gvkit
