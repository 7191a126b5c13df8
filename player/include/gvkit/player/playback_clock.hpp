#pragma once
// PlaybackClock: which frame to show now. Pure logic over an injectable clock, so tests drive
// time by hand. Play/pause, speed, loop, step and seek; frames are chosen by presentation
// timestamp, so sequences with uneven frame times play at their true pace.

#include <cstdint>
#include <functional>
#include <vector>

#include "gvkit/core/status.hpp"
#include "gvkit/core/timestamp.hpp"

namespace gvkit::player {

// Index of the frame to show at time t: the last frame whose timestamp is <= t (0 before the
// first). timestamps must be non-decreasing and non-empty (contract).
int64_t frame_at_time(const std::vector<Timestamp>& timestamps, Timestamp t);

class PlaybackClock {
 public:
  using NowFn = std::function<Timestamp()>;

  // Uniform frames: frame i is shown from i / fps. frame_count >= 1 and fps > 0 (contract).
  // now defaults to the monotonic clock. Starts paused at frame 0, speed 1, looping.
  PlaybackClock(int64_t frame_count, double fps, NowFn now = monotonic_now);
  // Frames with their own presentation times (relative to the first, non-decreasing); the last
  // frame lasts one nominal frame period (1 / fps).
  PlaybackClock(std::vector<Timestamp> timestamps, double fps, NowFn now = monotonic_now);

  void play();
  void pause();
  void toggle() { playing() ? pause() : play(); }
  bool playing() const { return playing_; }

  // Playback rate, > 0 (1 = real time). Fails on a value <= 0 or not finite.
  Status set_speed(double speed);
  double speed() const { return speed_; }
  // At the end, a looping clock wraps to frame 0; otherwise it stops on the last frame.
  void set_loop(bool loop) { loop_ = loop; }
  bool loop() const { return loop_; }

  // Shows frame `index` (clamped to the range) from now on; keeps playing if it was.
  void seek(int64_t index);
  // Seeks to a presentation time (clamped to [0, duration)).
  void seek_time(Timestamp t);
  // Pauses and moves `delta` frames (wrapping when looping, else clamped).
  void step(int64_t delta);

  // The frame to show now. Not const: a non-looping clock that reaches the end pauses.
  int64_t current_frame();
  // Presentation time now, in [0, duration).
  Timestamp position();
  Timestamp duration() const { return duration_; }
  int64_t frame_count() const { return static_cast<int64_t>(timestamps_.size()); }

 private:
  Timestamp raw_position() const;
  void anchor(Timestamp position);

  std::vector<Timestamp> timestamps_;
  Timestamp duration_{0};
  NowFn now_;
  bool playing_ = false, loop_ = true;
  double speed_ = 1.0;
  Timestamp anchor_position_{0};  // presentation time at anchor_wall_
  Timestamp anchor_wall_{0};
};

}  // namespace gvkit::player
