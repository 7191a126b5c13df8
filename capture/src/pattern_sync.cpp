#include "gvkit/capture/pattern_sync.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <utility>

namespace gvkit {
namespace {

// Pearson correlation of a and b[(i + rotation) % n]; 0 when either is constant.
double pearson(const std::vector<double>& a, const std::vector<double>& b, size_t rotation) {
  const size_t n = a.size();
  double ma = 0, mb = 0;
  for (size_t i = 0; i < n; ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= static_cast<double>(n);
  mb /= static_cast<double>(n);
  double sab = 0, saa = 0, sbb = 0;
  for (size_t i = 0; i < n; ++i) {
    const double da = a[i] - ma, db = b[(i + rotation) % n] - mb;
    sab += da * db;
    saa += da * da;
    sbb += db * db;
  }
  if (saa <= 0 || sbb <= 0) return 0;
  return sab / std::sqrt(saa * sbb);
}

}  // namespace

FringeSet to_fringe_set(FrameGroup group) {
  FringeSet set;
  set.images = std::move(group.images);
  set.texture = std::move(group.texture);
  set.index = group.index;
  set.timestamp = group.timestamp;
  return set;
}

// ---- software sync ----

Status SoftwareSyncOptions::check() const {
  if (patterns_per_cycle < 1)
    return invalid_argument("software sync: patterns_per_cycle " +
                            std::to_string(patterns_per_cycle) + " must be >= 1");
  if (display_latency.count() < 0 || default_exposure.count() < 0 || stream_end.count() < 0)
    return invalid_argument("software sync: latency, exposure and stream end must be >= 0");
  return Status::ok();
}

SoftwareSyncResult match_software_sync(const std::vector<PatternPresentation>& presentations,
                                       const std::vector<CameraFrame>& frames,
                                       const SoftwareSyncOptions& options) {
  GVKIT_CHECK(options.check().is_ok(), options.check().message());
  const int n = options.patterns_per_cycle;
  SoftwareSyncResult result;
  result.counters.frames_in = static_cast<int64_t>(frames.size());

  std::vector<size_t> by_time(presentations.size());
  std::iota(by_time.begin(), by_time.end(), size_t{0});
  std::stable_sort(by_time.begin(), by_time.end(), [&](size_t a, size_t b) {
    return presentations[a].presented < presentations[b].presented;
  });
  std::vector<size_t> frame_order(frames.size());
  std::iota(frame_order.begin(), frame_order.end(), size_t{0});
  std::stable_sort(frame_order.begin(), frame_order.end(),
                   [&](size_t a, size_t b) { return frames[a].timestamp < frames[b].timestamp; });
  auto exposure_end = [&](const CameraFrame& f) {
    return f.timestamp + (f.exposure.count() > 0 ? f.exposure : options.default_exposure);
  };

  // The frame (index into frames) seen under each presentation, by presentation index.
  std::vector<std::optional<size_t>> seen(presentations.size());
  size_t next_frame = 0;
  const Timestamp open_end = Timestamp::max();
  for (size_t t = 0; t < by_time.size(); ++t) {
    const Timestamp start = presentations[by_time[t]].presented + options.display_latency;
    const Timestamp end =
        t + 1 < by_time.size() ? presentations[by_time[t + 1]].presented + options.display_latency
        : options.stream_end.count() > 0 ? options.stream_end + options.display_latency
                                         : open_end;
    while (next_frame < frame_order.size() && frames[frame_order[next_frame]].timestamp < start)
      ++next_frame;
    for (size_t k = next_frame; k < frame_order.size() && frames[frame_order[k]].timestamp < end;
         ++k) {
      if (exposure_end(frames[frame_order[k]]) <= end) {
        seen[by_time[t]] = frame_order[k];
        next_frame = k + 1;
        break;
      }
    }
  }

  // Cycle by cycle: every pattern shown exactly once and seen by a frame, or the cycle is dropped.
  std::map<int64_t, std::vector<std::vector<size_t>>> cycles;  // cycle -> pattern -> presentations
  std::map<int64_t, std::string> broken;
  for (size_t p = 0; p < presentations.size(); ++p) {
    auto& slots = cycles[presentations[p].cycle];
    slots.resize(static_cast<size_t>(n));
    const int k = presentations[p].pattern;
    if (k < 0 || k >= n)
      broken[presentations[p].cycle] =
          "pattern index " + std::to_string(k) + " is outside 0.." + std::to_string(n - 1);
    else
      slots[static_cast<size_t>(k)].push_back(p);
  }
  for (auto& [cycle, slots] : cycles) {
    std::string problem = broken.count(cycle) ? broken[cycle] : std::string();
    FrameGroup group;
    for (int k = 0; k < n && problem.empty(); ++k) {
      const auto& shown = slots[static_cast<size_t>(k)];
      if (shown.empty())
        problem = "pattern " + std::to_string(k) + " was never shown";
      else if (shown.size() > 1)
        problem = "pattern " + std::to_string(k) + " was shown " + std::to_string(shown.size()) +
                  " times";
      else if (!seen[shown[0]])
        problem = "pattern " + std::to_string(k) + ": no frame exposed wholly while it showed";
      else {
        const CameraFrame& f = frames[*seen[shown[0]]];
        group.images.push_back(f.image);
        group.sequences.push_back(f.sequence);
        if (k == 0 || f.timestamp < group.timestamp) group.timestamp = f.timestamp;
      }
    }
    if (!problem.empty()) {
      ++result.counters.cycles_dropped;
      result.dropped.push_back("cycle " + std::to_string(cycle) + ": " + problem);
      continue;
    }
    group.index = result.counters.groups++;
    result.groups.push_back(std::move(group));
  }
  result.counters.frames_unused = result.counters.frames_in - result.counters.groups * n;
  return result;
}

SoftwareSyncStream::SoftwareSyncStream(SoftwareSyncOptions options) : options_(options) {
  GVKIT_CHECK(options_.check().is_ok(), options_.check().message());
  options_.stream_end = Timestamp(0);
}

void SoftwareSyncStream::presented(const PatternPresentation& presentation) {
  std::lock_guard<std::mutex> lock(mutex_);
  presentations_.push_back(presentation);
}

SyncCounters SoftwareSyncStream::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

std::optional<FrameGroup> SoftwareSyncStream::push(const CameraFrame& frame) {
  std::lock_guard<std::mutex> lock(mutex_);
  frames_.push_back(frame);
  ++counters_.frames_in;
  const int n = options_.patterns_per_cycle;
  while (!presentations_.empty()) {
    // The oldest cycle, and the first presentation of a later one (where this cycle ends).
    const int64_t cycle = presentations_.front().cycle;
    std::vector<PatternPresentation> mine;
    std::optional<Timestamp> end;
    for (const PatternPresentation& p : presentations_) {
      if (p.cycle == cycle)
        mine.push_back(p);
      else if (p.cycle > cycle && (!end || p.presented < *end))
        end = p.presented;
    }
    if (!end) return std::nullopt;
    const Timestamp end_seen = *end + options_.display_latency;
    if (frames_.back().timestamp < end_seen) return std::nullopt;  // frames may still come
    SoftwareSyncOptions o = options_;
    o.stream_end = *end;
    std::vector<CameraFrame> window;
    while (!frames_.empty() && frames_.front().timestamp < end_seen) {
      window.push_back(std::move(frames_.front()));
      frames_.pop_front();
    }
    SoftwareSyncResult r = match_software_sync(mine, window, o);
    presentations_.erase(
        std::remove_if(presentations_.begin(), presentations_.end(),
                       [&](const PatternPresentation& p) { return p.cycle == cycle; }),
        presentations_.end());
    if (r.groups.empty()) {
      ++counters_.cycles_dropped;
      counters_.frames_unused += static_cast<int64_t>(window.size());
      continue;
    }
    counters_.frames_unused += static_cast<int64_t>(window.size()) - n;
    FrameGroup group = std::move(r.groups.front());
    group.index = cycle;
    ++counters_.groups;
    return group;
  }
  return std::nullopt;
}

// ---- hardware-triggered projector ----

Status HardwareSyncOptions::check() const {
  const int n = static_cast<int>(signature.size());
  if (n < 2) return invalid_argument("hardware sync: the signature needs at least 2 entries");
  std::vector<double> self(signature);
  for (int r = 1; r < n; ++r)
    if (pearson(signature, self, static_cast<size_t>(r)) >= min_correlation)
      return invalid_argument("hardware sync: the signature looks the same shifted by " +
                              std::to_string(r) + " frames, so it cannot find the cycle start");
  if (pearson(signature, self, 0) <= 0)
    return invalid_argument("hardware sync: a constant signature cannot find the cycle start");
  if (texture_position < -1 || texture_position >= n)
    return invalid_argument("hardware sync: texture_position " + std::to_string(texture_position) +
                            " is outside the cycle of " + std::to_string(n));
  for (int p : fringe_positions)
    if (p < 0 || p >= n)
      return invalid_argument("hardware sync: fringe position " + std::to_string(p) +
                              " is outside the cycle of " + std::to_string(n));
  if (!(min_correlation > 0 && min_correlation <= 1))
    return invalid_argument("hardware sync: min_correlation must be in (0, 1]");
  if (!(min_contrast >= 0 && min_contrast < 1))
    return invalid_argument("hardware sync: min_contrast must be in [0, 1)");
  return Status::ok();
}

HardwareSyncOptions HardwareSyncOptions::cue(int n_fringes, bool bright) {
  HardwareSyncOptions o;
  o.signature.assign(static_cast<size_t>(n_fringes) + 1, 0.5);
  o.signature[0] = bright ? 1.0 : 0.0;
  for (int i = 1; i <= n_fringes; ++i) o.fringe_positions.push_back(i);
  o.texture_position = bright ? 0 : -1;
  return o;
}

HardwareTriggeredSync::HardwareTriggeredSync(HardwareSyncOptions options)
    : options_(std::move(options)), n_(options_.signature.size()) {
  GVKIT_CHECK(options_.check().is_ok(), options_.check().message());
  if (options_.fringe_positions.empty())
    for (int p = 0; p < static_cast<int>(n_); ++p)
      if (p != options_.texture_position) options_.fringe_positions.push_back(p);
}

double HardwareTriggeredSync::correlation(const std::deque<Seen>& cycle, size_t rotation) const {
  std::vector<double> means;
  for (const Seen& s : cycle) means.push_back(s.mean);
  return pearson(means, options_.signature, rotation);
}

bool HardwareTriggeredSync::matches(const std::deque<Seen>& cycle) const {
  if (cycle.size() != n_) return false;
  const double full_scale = cycle.front().frame.image.depth() == CV_16U ? 65535.0 : 255.0;
  const auto [lo, hi] = std::minmax_element(
      cycle.begin(), cycle.end(), [](const Seen& a, const Seen& b) { return a.mean < b.mean; });
  if ((hi->mean - lo->mean) < options_.min_contrast * full_scale) return false;
  const double at_start = correlation(cycle, 0);
  if (at_start < options_.min_correlation) return false;
  for (size_t r = 1; r < n_; ++r)
    if (correlation(cycle, r) >= at_start) return false;  // the phase must be unambiguous
  return true;
}

FrameGroup HardwareTriggeredSync::emit(std::deque<Seen>& cycle) {
  FrameGroup group;
  for (int p : options_.fringe_positions)
    group.images.push_back(cycle[static_cast<size_t>(p)].frame.image);
  if (options_.texture_position >= 0)
    group.texture = cycle[static_cast<size_t>(options_.texture_position)].frame.image;
  for (const Seen& s : cycle) group.sequences.push_back(s.frame.sequence);
  group.timestamp = cycle.front().frame.timestamp;
  group.index = counters_.groups++;
  cycle.clear();
  return group;
}

void HardwareTriggeredSync::drop_cycle_in_progress() {
  if (locked_ && !window_.empty()) ++counters_.cycles_dropped;
  counters_.frames_unused += static_cast<int64_t>(window_.size());
  window_.clear();
  locked_ = false;
}

std::optional<FrameGroup> HardwareTriggeredSync::push(const CameraFrame& frame) {
  ++counters_.frames_in;
  if (last_sequence_ && frame.sequence != *last_sequence_ + 1) drop_cycle_in_progress();
  last_sequence_ = frame.sequence;
  window_.push_back({frame, cv::mean(frame.image)[0]});
  if (locked_) {
    if (window_.size() < n_) return std::nullopt;
    if (matches(window_)) return emit(window_);
    ++counters_.cycles_dropped;  // the cycle did not look like one: lost sync
    locked_ = false;
    return std::nullopt;  // keep the frames: the search may find the cycle start among them
  }
  if (window_.size() > n_) {
    window_.pop_front();
    ++counters_.frames_unused;
  }
  if (window_.size() == n_ && matches(window_)) {
    locked_ = true;
    return emit(window_);
  }
  return std::nullopt;
}

void HardwareTriggeredSync::finish() { drop_cycle_in_progress(); }

// ---- tagged frames ----

Status TaggedSyncOptions::check() const {
  if (patterns_per_cycle < 1 || patterns_per_cycle > 1024)
    return invalid_argument("tagged sync: patterns_per_cycle " +
                            std::to_string(patterns_per_cycle) + " is outside 1..1024");
  if (frames_per_cycle < patterns_per_cycle || frames_per_cycle > 1024)
    return invalid_argument("tagged sync: frames_per_cycle " + std::to_string(frames_per_cycle) +
                            " must be in patterns_per_cycle..1024");
  return Status::ok();
}

TaggedPatternSync::TaggedPatternSync(TaggedSyncOptions options) : options_(options) {
  GVKIT_CHECK(options_.check().is_ok(), options_.check().message());
}

void TaggedPatternSync::drop(const std::string& why) {
  if (cycle_ >= 0 && have_ > 0) {
    ++counters_.cycles_dropped;
    counters_.frames_unused += have_;
    dropped_.push_back("cycle " + std::to_string(cycle_) + ": " + why);
    if (dropped_.size() > 100) dropped_.pop_front();
  }
  frames_.clear();
  have_ = 0;
}

std::optional<FrameGroup> TaggedPatternSync::push(const CameraFrame& frame) {
  ++counters_.frames_in;
  const int n = options_.patterns_per_cycle;
  if (frame.pattern < 0 || frame.pattern >= n || frame.sequence < 0) {
    ++counters_.frames_unused;  // a cue or an untagged frame
    return std::nullopt;
  }
  const int64_t cycle = frame.sequence / options_.frames_per_cycle;
  if (cycle != cycle_) {
    if (have_ > 0) {
      int missing = 0;
      while (missing < n && !frames_[static_cast<size_t>(missing)].image.empty()) ++missing;
      drop("pattern " + std::to_string(missing) + " never arrived");
    }
    cycle_ = cycle;
    frames_.assign(static_cast<size_t>(n), CameraFrame());
  }
  CameraFrame& slot = frames_[static_cast<size_t>(frame.pattern)];
  if (!slot.image.empty()) {
    drop("pattern " + std::to_string(frame.pattern) + " arrived twice");
    cycle_ = -1;
    ++counters_.frames_unused;
    return std::nullopt;
  }
  slot = frame;
  if (++have_ < n) return std::nullopt;
  FrameGroup group;
  for (CameraFrame& f : frames_) {
    group.images.push_back(f.image);
    group.sequences.push_back(f.sequence);
  }
  group.timestamp = frames_.front().timestamp;
  group.index = cycle_;
  ++counters_.groups;
  frames_.clear();
  have_ = 0;
  cycle_ = -1;
  return group;
}

void TaggedPatternSync::finish() { drop("the stream ended"); }

}  // namespace gvkit
