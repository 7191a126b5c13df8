#include "gvkit/player/playback_clock.hpp"

#include <algorithm>
#include <cmath>

namespace gvkit::player {
namespace {

std::vector<Timestamp> uniform_timestamps(int64_t frame_count, double fps) {
  GVKIT_CHECK(frame_count >= 1, "a clock needs at least one frame");
  GVKIT_CHECK(fps > 0 && std::isfinite(fps), "fps must be > 0");
  std::vector<Timestamp> t(static_cast<size_t>(frame_count));
  for (int64_t i = 0; i < frame_count; ++i)
    t[static_cast<size_t>(i)] = Timestamp(static_cast<int64_t>(std::llround(i * 1e9 / fps)));
  return t;
}

}  // namespace

int64_t frame_at_time(const std::vector<Timestamp>& timestamps, Timestamp t) {
  GVKIT_CHECK(!timestamps.empty(), "no frames");
  const auto it = std::upper_bound(timestamps.begin(), timestamps.end(), t);
  if (it == timestamps.begin()) return 0;
  return static_cast<int64_t>(it - timestamps.begin()) - 1;
}

PlaybackClock::PlaybackClock(int64_t frame_count, double fps, NowFn now)
    : PlaybackClock(uniform_timestamps(frame_count, fps), fps, std::move(now)) {}

PlaybackClock::PlaybackClock(std::vector<Timestamp> timestamps, double fps, NowFn now)
    : timestamps_(std::move(timestamps)), now_(std::move(now)) {
  GVKIT_CHECK(!timestamps_.empty(), "a clock needs at least one frame");
  GVKIT_CHECK(fps > 0 && std::isfinite(fps), "fps must be > 0");
  GVKIT_CHECK(std::is_sorted(timestamps_.begin(), timestamps_.end()),
              "timestamps must not decrease");
  // Relative to the first frame.
  const Timestamp first = timestamps_.front();
  for (auto& t : timestamps_) t -= first;
  duration_ = timestamps_.back() + Timestamp(static_cast<int64_t>(std::llround(1e9 / fps)));
  anchor_wall_ = now_();
}

Timestamp PlaybackClock::raw_position() const {
  if (!playing_) return anchor_position_;
  const double elapsed = static_cast<double>((now_() - anchor_wall_).count()) * speed_;
  return anchor_position_ + Timestamp(static_cast<int64_t>(elapsed));
}

void PlaybackClock::anchor(Timestamp position) {
  anchor_position_ = position;
  anchor_wall_ = now_();
}

void PlaybackClock::play() {
  if (playing_) return;
  // Playing from the end of a finished, non-looping clip starts it again.
  if (!loop_ && anchor_position_ >= timestamps_.back()) anchor_position_ = Timestamp(0);
  anchor(anchor_position_);
  playing_ = true;
}

void PlaybackClock::pause() {
  if (!playing_) return;
  anchor(position());
  playing_ = false;
}

Status PlaybackClock::set_speed(double speed) {
  if (!(speed > 0) || !std::isfinite(speed))
    return invalid_argument("playback speed must be > 0, got " + std::to_string(speed));
  anchor(position());
  speed_ = speed;
  return Status::ok();
}

void PlaybackClock::seek(int64_t index) {
  index = std::clamp<int64_t>(index, 0, frame_count() - 1);
  anchor(timestamps_[static_cast<size_t>(index)]);
}

void PlaybackClock::seek_time(Timestamp t) {
  anchor(std::clamp(t, Timestamp(0), duration_ - Timestamp(1)));
}

void PlaybackClock::step(int64_t delta) {
  pause();
  int64_t index = current_frame() + delta;
  const int64_t n = frame_count();
  index = loop_ ? ((index % n) + n) % n : std::clamp<int64_t>(index, 0, n - 1);
  anchor(timestamps_[static_cast<size_t>(index)]);
}

Timestamp PlaybackClock::position() {
  Timestamp p = raw_position();
  if (p < duration_) return std::max(p, Timestamp(0));
  if (loop_) return Timestamp(p.count() % duration_.count());
  // Stop on the last frame.
  playing_ = false;
  anchor(timestamps_.back());
  return timestamps_.back();
}

int64_t PlaybackClock::current_frame() { return frame_at_time(timestamps_, position()); }

}  // namespace gvkit::player
