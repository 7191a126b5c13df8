#pragma once
// Frame <-> pattern association: which camera frame saw which projected pattern.
//  (a) Software sync: the program shows pattern k and records when it became visible
//      (PatternPresentation); the frame for pattern k is the first one whose whole exposure lies
//      after that moment and before the next pattern appeared.
//  (b) A hardware-triggered projector that sequences the patterns itself: frames arrive one per
//      pattern in a fixed order with unknown phase. The cycle start is found from the images, by
//      the mean-intensity signature of one cycle (a bright or dark cue frame is the usual one),
//      checked again on every cycle; after a dropped frame or a cycle that does not match, the
//      incomplete cycle is dropped and counted and the sync searches again.
//  (c) Tagged frames: the source knows which pattern each frame saw (CameraFrame::pattern; the
//      synthetic rig and the replay of a session folder), so a cycle is complete when patterns
//      0..n-1 of one cycle arrived.
// None ever pairs a frame with the wrong pattern silently: a cycle that cannot be matched
// completely is dropped and counted.

#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/capture/frame_source.hpp"
#include "gvkit/core/fringe_set.hpp"

namespace gvkit {

// One complete cycle of patterns with its frames, ready to become a FringeSet.
struct FrameGroup {
  std::vector<cv::Mat> images;  // images[k]: the frame under fringe pattern k
  cv::Mat texture;              // a flat-lit frame when the cycle has one (bright cue), else empty
  int64_t index = 0;            // cycle number among the emitted groups, from 0
  Timestamp timestamp{0};       // timestamp of the cycle's first frame
  std::vector<int64_t> sequences;  // the source sequence numbers used, in pattern order
};

FringeSet to_fringe_set(FrameGroup group);

// What a sync has done: frames seen, groups emitted, cycles dropped (incomplete or mismatched),
// frames that went into no group.
struct SyncCounters {
  int64_t frames_in = 0;
  int64_t groups = 0;
  int64_t cycles_dropped = 0;
  int64_t frames_unused = 0;
};

// ---- (a) software sync ----

struct PatternPresentation {
  int64_t cycle = 0;       // which repetition of the pattern set
  int pattern = 0;         // position in the set, 0..patterns_per_cycle-1
  Timestamp presented{0};  // monotonic time it became visible (after buffer swap + glFinish)
};

struct SoftwareSyncOptions {
  int patterns_per_cycle = 3;
  Timestamp display_latency{0};   // added to every presentation time (projector scan-out lag)
  Timestamp default_exposure{0};  // exposure of frames that report none (CameraFrame::exposure 0)
  Timestamp stream_end{0};        // when the last pattern stopped showing; 0 = still showing
  Status check() const;
};

struct SoftwareSyncResult {
  std::vector<FrameGroup> groups;
  SyncCounters counters;
  std::vector<std::string> dropped;  // one line per dropped cycle: which pattern lacked a frame
};

// Frame exposure is [timestamp, timestamp + exposure]. Presentations may come in any order;
// pattern k of a cycle is visible from its presentation time (+ latency) until the next
// presentation in time (+ latency). Each frame is used at most once. A cycle with a pattern
// that no frame saw wholly, or with a pattern shown twice or never, is dropped.
SoftwareSyncResult match_software_sync(const std::vector<PatternPresentation>& presentations,
                                       const std::vector<CameraFrame>& frames,
                                       const SoftwareSyncOptions& options);

// (a) live: presentations (from the projector loop) and frames (from the camera) arrive as they
// happen, on two threads. A cycle is matched with match_software_sync once the next cycle's first
// presentation is known and a frame later than it arrived; it is then complete or dropped.
class SoftwareSyncStream {
 public:
  // options.stream_end is ignored (the next cycle's first presentation ends each cycle).
  explicit SoftwareSyncStream(SoftwareSyncOptions options);

  // Thread-safe; presentations of a cycle must come before those of later cycles.
  void presented(const PatternPresentation& presentation);
  // Feeds the next camera frame (timestamps non-decreasing; one thread). Returns the oldest
  // cycle it completes; group index = the presentation cycle number.
  std::optional<FrameGroup> push(const CameraFrame& frame);

  SyncCounters counters() const;

 private:
  SoftwareSyncOptions options_;
  mutable std::mutex mutex_;  // guards presentations_ and counters_
  std::vector<PatternPresentation> presentations_;
  std::deque<CameraFrame> frames_;
  SyncCounters counters_;
};

// ---- (b) hardware-triggered projector ----

struct HardwareSyncOptions {
  // Expected mean intensity of each frame of one cycle, in cycle order (any scale: compared by
  // correlation). {1, 0.5, 0.5, 0.5} = a white cue then three fringe patterns.
  std::vector<double> signature;
  // Positions in the cycle that are fringe images (empty = all but texture_position), and the
  // position of a flat-lit frame used as texture (-1 = none).
  std::vector<int> fringe_positions;
  int texture_position = -1;
  double min_correlation = 0.9;  // a cycle matches when its means correlate this well
  // A cycle whose means spread less than this share of the full scale (255 or 65535) is not
  // trusted (projector off, lens cap): it is dropped.
  double min_contrast = 0.02;
  Status check() const;
  // A white (bright = true) or black cue frame, then n_fringes fringe frames; the white cue
  // becomes the texture.
  static HardwareSyncOptions cue(int n_fringes, bool bright = true);
};

class HardwareTriggeredSync {
 public:
  explicit HardwareTriggeredSync(HardwareSyncOptions options);

  // Feeds the next frame of the stream (in arrival order). Returns a group when this frame
  // completes a verified cycle. A gap in sequence numbers drops the cycle in progress.
  std::optional<FrameGroup> push(const CameraFrame& frame);
  // Ends the stream: a cycle in progress is dropped and counted.
  void finish();

  bool locked() const { return locked_; }
  const SyncCounters& counters() const { return counters_; }

 private:
  struct Seen {
    CameraFrame frame;
    double mean;
  };
  double correlation(const std::deque<Seen>& cycle, size_t rotation) const;
  bool matches(const std::deque<Seen>& cycle) const;
  FrameGroup emit(std::deque<Seen>& cycle);
  void drop_cycle_in_progress();

  HardwareSyncOptions options_;
  size_t n_;
  std::deque<Seen> window_;  // searching: the last n frames; locked: the cycle in progress
  bool locked_ = false;
  std::optional<int64_t> last_sequence_;
  SyncCounters counters_;
};

// ---- (c) frames tagged with their pattern ----

struct TaggedSyncOptions {
  int patterns_per_cycle = 3;
  // Frames per cycle of the source (>= patterns_per_cycle; the extra frames, e.g. a cue, carry
  // pattern -1 and are ignored). Frame sequence s belongs to cycle s / frames_per_cycle.
  int frames_per_cycle = 3;
  Status check() const;
};

class TaggedPatternSync {
 public:
  explicit TaggedPatternSync(TaggedSyncOptions options);

  // Feeds the next frame (arrival order). Returns a group when the frame completes its cycle;
  // the group's index is the cycle number (sequence / frames_per_cycle), so dropped cycles leave
  // gaps. A cycle that lacks a pattern, or repeats one, is dropped and counted.
  std::optional<FrameGroup> push(const CameraFrame& frame);
  // Ends the stream: a cycle in progress is dropped and counted.
  void finish();

  const SyncCounters& counters() const { return counters_; }
  // One line per dropped cycle (the last 100): which cycle and why.
  const std::deque<std::string>& dropped() const { return dropped_; }

 private:
  void drop(const std::string& why);

  TaggedSyncOptions options_;
  int64_t cycle_ = -1;               // the cycle in progress
  std::vector<CameraFrame> frames_;  // its frames by pattern (empty image = not yet)
  int have_ = 0;
  SyncCounters counters_;
  std::deque<std::string> dropped_;
};

}  // namespace gvkit
