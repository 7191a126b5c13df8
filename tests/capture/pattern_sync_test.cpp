// Frame <-> pattern association: software sync on presentation times and exposure intervals, and
// cycle finding for a hardware-triggered projector, with drops, jitter and mismatches.
#include "gvkit/capture/pattern_sync.hpp"

#include <gtest/gtest.h>

#include <random>

namespace gvkit {
namespace {
using std::chrono::milliseconds;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A 4x4 frame whose pixels all equal `value` (the frame "shows" that value).
CameraFrame frame_at(int64_t sequence, Timestamp start, Timestamp exposure, uint8_t value) {
  CameraFrame f;
  f.image = cv::Mat(4, 4, CV_8U, cv::Scalar(value));
  f.sequence = sequence;
  f.timestamp = start;
  f.exposure = exposure;
  return f;
}

int value_of(const cv::Mat& image) { return image.at<uint8_t>(0, 0); }

// ---- software sync ----

// Patterns shown every 100 ms; camera at 40 fps (25 ms period), 10 ms exposure, starting at
// `camera_offset`. Each frame's value tells which pattern was on screen during its exposure
// (200 + pattern), or 0 when the exposure straddles a switch.
struct SoftwareScene {
  std::vector<PatternPresentation> shown;
  std::vector<CameraFrame> frames;
};

SoftwareScene make_scene(int cycles, int n, Timestamp camera_offset) {
  SoftwareScene scene;
  const Timestamp period = milliseconds(100);
  for (int c = 0; c < cycles; ++c)
    for (int k = 0; k < n; ++k) scene.shown.push_back({c, k, period * (c * n + k)});
  const Timestamp end = period * (cycles * n);
  for (int64_t i = 0;; ++i) {
    const Timestamp start = camera_offset + milliseconds(25) * i;
    const Timestamp stop = start + milliseconds(10);
    if (stop > end) break;
    const int64_t slot = start / period;
    const bool whole = stop <= period * (slot + 1);
    scene.frames.push_back(
        frame_at(i, start, milliseconds(10), whole ? static_cast<uint8_t>(200 + slot % n) : 0));
  }
  return scene;
}

TEST(SoftwareSync, PicksTheFirstFrameExposedWhollyAfterEachPresentation) {
  for (const int offset_ms : {0, 3, 17, 24}) {
    SoftwareScene scene = make_scene(4, 3, milliseconds(offset_ms));
    SoftwareSyncOptions o;
    o.patterns_per_cycle = 3;
    o.stream_end = milliseconds(1200);
    const SoftwareSyncResult r = match_software_sync(scene.shown, scene.frames, o);
    ASSERT_EQ(r.groups.size(), 4u) << "offset " << offset_ms;
    EXPECT_EQ(r.counters.cycles_dropped, 0);
    for (const FrameGroup& g : r.groups) {
      ASSERT_EQ(g.images.size(), 3u);
      for (int k = 0; k < 3; ++k) EXPECT_EQ(value_of(g.images[k]), 200 + k);
      // The first frame wholly after the presentation: starts within one camera period of it.
      EXPECT_GE(g.timestamp, milliseconds(300) * g.index);
      EXPECT_LT(g.timestamp, milliseconds(300) * g.index + milliseconds(25));
    }
    EXPECT_EQ(r.counters.frames_unused, r.counters.frames_in - 12);
  }
}

TEST(SoftwareSync, FramesInAnyOrderAndUnknownExposureUseTheDefault) {
  SoftwareScene scene = make_scene(2, 3, milliseconds(5));
  std::reverse(scene.frames.begin(), scene.frames.end());
  for (auto& f : scene.frames) f.exposure = Timestamp(0);
  SoftwareSyncOptions o;
  o.default_exposure = milliseconds(10);
  const SoftwareSyncResult r = match_software_sync(scene.shown, scene.frames, o);
  ASSERT_EQ(r.groups.size(), 2u);
  for (const FrameGroup& g : r.groups)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(value_of(g.images[k]), 200 + k);
}

TEST(SoftwareSync, DisplayLatencyShiftsTheWindows) {
  // The projector shows each pattern 30 ms after the program presented it: frames are generated
  // against the shifted times, the presentations keep the program's times.
  SoftwareScene scene = make_scene(2, 3, milliseconds(2));
  for (auto& p : scene.shown) p.presented -= milliseconds(30);
  SoftwareSyncOptions o;
  const SoftwareSyncResult without = match_software_sync(scene.shown, scene.frames, o);
  o.display_latency = milliseconds(30);
  const SoftwareSyncResult with = match_software_sync(scene.shown, scene.frames, o);
  ASSERT_EQ(with.groups.size(), 2u);
  for (const FrameGroup& g : with.groups)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(value_of(g.images[k]), 200 + k);
  // Without the latency the first frame after a presentation still shows the previous pattern.
  bool wrong = false;
  for (const FrameGroup& g : without.groups)
    for (int k = 0; k < 3; ++k) wrong |= value_of(g.images[k]) != 200 + k;
  EXPECT_TRUE(wrong);
}

TEST(SoftwareSync, ACycleMissingAFrameIsDroppedAndNamed) {
  SoftwareScene scene = make_scene(3, 3, milliseconds(4));
  // Remove every frame that starts while cycle 1's pattern 2 shows (500..600 ms).
  std::erase_if(scene.frames, [](const CameraFrame& f) {
    return f.timestamp >= milliseconds(500) && f.timestamp < milliseconds(600);
  });
  const SoftwareSyncResult r = match_software_sync(scene.shown, scene.frames, {});
  ASSERT_EQ(r.groups.size(), 2u);
  EXPECT_EQ(r.counters.cycles_dropped, 1);
  ASSERT_EQ(r.dropped.size(), 1u);
  EXPECT_EQ(r.dropped[0], "cycle 1: pattern 2: no frame exposed wholly while it showed");
  EXPECT_EQ(r.groups[1].index, 1);
  EXPECT_EQ(value_of(r.groups[1].images[2]), 202);  // cycle 2 is intact
}

TEST(SoftwareSync, ExposuresLongerThanAPatternNeverMatch) {
  SoftwareScene scene = make_scene(1, 3, milliseconds(0));
  for (auto& f : scene.frames) f.exposure = milliseconds(150);
  const SoftwareSyncResult r = match_software_sync(scene.shown, scene.frames, {});
  EXPECT_TRUE(r.groups.empty());
  EXPECT_EQ(r.counters.cycles_dropped, 1);
}

TEST(SoftwareSync, BrokenPresentationListsDropTheirCycle) {
  SoftwareScene scene = make_scene(3, 3, milliseconds(4));
  scene.shown.erase(scene.shown.begin() + 1);  // cycle 0 pattern 1 never shown
  scene.shown[4].pattern = 0;                  // cycle 1 shows pattern 0 twice
  scene.shown[7].pattern = 5;                  // cycle 2 has an index out of range
  const SoftwareSyncResult r = match_software_sync(scene.shown, scene.frames, {});
  EXPECT_TRUE(r.groups.empty());
  ASSERT_EQ(r.dropped.size(), 3u);
  EXPECT_TRUE(contains(r.dropped[0], "cycle 0: pattern 1 was never shown"));
  EXPECT_TRUE(contains(r.dropped[1], "cycle 1: pattern 0 was shown 2 times"));
  EXPECT_TRUE(contains(r.dropped[2], "cycle 2: pattern index 5"));
}

// ---- hardware-triggered projector ----

// The camera sees, frame after frame, a white cue (value 250) then three fringe frames
// (120 + 10 * k, slightly different so misplacements show), cycling, starting at `phase`.
std::vector<CameraFrame> triggered_stream(int n_frames, int phase, uint16_t depth_scale = 1) {
  std::vector<CameraFrame> frames;
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> noise(-3, 3);
  for (int i = 0; i < n_frames; ++i) {
    const int position = (i + phase) % 4;
    const int value = position == 0 ? 250 : 120 + 10 * position + noise(rng);
    CameraFrame f;
    f.image = cv::Mat(4, 4, depth_scale == 1 ? CV_8U : CV_16U, cv::Scalar(value * depth_scale));
    f.sequence = i;
    f.timestamp = milliseconds(10) * i;
    f.image.at<uint8_t>(0, 0) = static_cast<uint8_t>(depth_scale == 1 ? position : 0);
    frames.push_back(f);
  }
  return frames;
}

// Position in the cycle that produced this frame (stored in pixel (0,0)).
int position_of(const cv::Mat& image) { return image.at<uint8_t>(0, 0); }

void expect_well_formed(const FrameGroup& g) {
  ASSERT_EQ(g.images.size(), 3u);
  EXPECT_EQ(position_of(g.texture), 0);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(position_of(g.images[k]), k + 1);
  for (size_t i = 1; i < g.sequences.size(); ++i) EXPECT_EQ(g.sequences[i], g.sequences[i - 1] + 1);
}

TEST(HardwareSync, FindsTheCycleStartAtAnyPhase) {
  for (int phase = 0; phase < 4; ++phase) {
    HardwareTriggeredSync sync(HardwareSyncOptions::cue(3));
    std::vector<FrameGroup> groups;
    for (const CameraFrame& f : triggered_stream(22, phase))
      if (auto g = sync.push(f)) groups.push_back(std::move(*g));
    sync.finish();
    // 22 frames from phase p hold floor((22 - (4 - p) % 4) / 4) complete cycles.
    const int skipped = (4 - phase) % 4;
    ASSERT_EQ(static_cast<int>(groups.size()), (22 - skipped) / 4) << "phase " << phase;
    for (const FrameGroup& g : groups) expect_well_formed(g);
    EXPECT_EQ(groups[0].sequences[0], skipped);
    const SyncCounters& c = sync.counters();
    EXPECT_EQ(c.frames_in, 22);
    EXPECT_EQ(c.frames_unused, 22 - 4 * c.groups);
  }
}

TEST(HardwareSync, ADroppedFrameDropsItsCycleAndResyncs) {
  std::vector<CameraFrame> stream = triggered_stream(24, 0);
  stream.erase(stream.begin() + 6);  // frame 6 (cycle 1, position 2) never arrived
  HardwareTriggeredSync sync(HardwareSyncOptions::cue(3));
  std::vector<FrameGroup> groups;
  for (const CameraFrame& f : stream)
    if (auto g = sync.push(f)) groups.push_back(std::move(*g));
  sync.finish();
  ASSERT_EQ(groups.size(), 5u);  // cycles 0, 2, 3, 4, 5; cycle 1 lost
  for (const FrameGroup& g : groups) expect_well_formed(g);
  EXPECT_EQ(groups[1].sequences[0], 8);
  EXPECT_EQ(sync.counters().cycles_dropped, 1);
  EXPECT_EQ(sync.counters().frames_unused, 3);  // frames 4, 5 and 7
}

TEST(HardwareSync, AProjectorSkipWithoutSequenceGapIsCaughtByTheSignature) {
  // The projector skipped a pattern (no trigger-side gap): the camera's numbering is intact but
  // from frame 9 on every frame is one position ahead.
  std::vector<CameraFrame> stream = triggered_stream(9, 0);
  for (CameraFrame f : triggered_stream(16, 2)) {  // phase 2 == frame 9 at position 2 + ...
    f.sequence += 9;
    stream.push_back(f);
  }
  HardwareTriggeredSync sync(HardwareSyncOptions::cue(3));
  std::vector<FrameGroup> groups;
  for (const CameraFrame& f : stream)
    if (auto g = sync.push(f)) groups.push_back(std::move(*g));
  for (const FrameGroup& g : groups) expect_well_formed(g);  // never a wrong pairing
  EXPECT_EQ(sync.counters().cycles_dropped, 1);
  EXPECT_GE(groups.size(), 4u);
}

TEST(HardwareSync, DarkCueAnd16BitFrames) {
  HardwareSyncOptions o = HardwareSyncOptions::cue(3, /*bright=*/false);
  HardwareTriggeredSync sync(o);
  int groups = 0;
  for (int i = 0; i < 12; ++i) {
    const int position = i % 4;
    CameraFrame f;
    f.image = cv::Mat(4, 4, CV_16U, cv::Scalar(position == 0 ? 500 : 30000 + 100 * position));
    f.sequence = i;
    if (auto g = sync.push(f)) {
      ++groups;
      EXPECT_TRUE(g->texture.empty());
      EXPECT_EQ(g->images[0].at<uint16_t>(0, 0), 30100);
    }
  }
  EXPECT_EQ(groups, 3);
}

TEST(HardwareSync, AFlatStreamNeverLocks) {
  HardwareTriggeredSync sync(HardwareSyncOptions::cue(3));
  for (int i = 0; i < 20; ++i) {
    CameraFrame f;
    f.image = cv::Mat(4, 4, CV_8U, cv::Scalar(128 + (i % 4 == 0 ? 2 : 0)));  // 2/255 < 2 %
    f.sequence = i;
    EXPECT_FALSE(sync.push(f).has_value());
  }
  EXPECT_FALSE(sync.locked());
  EXPECT_EQ(sync.counters().groups, 0);
}

TEST(HardwareSync, OptionsRejectAmbiguousSignatures) {
  HardwareSyncOptions o;
  o.signature = {1, 0, 1, 0};
  EXPECT_TRUE(contains(o.check().message(), "shifted by 2 frames")) << o.check().message();
  o.signature = {1, 1, 1};
  EXPECT_FALSE(o.check().is_ok());
  o = HardwareSyncOptions::cue(3);
  EXPECT_TRUE(o.check().is_ok());
  o.texture_position = 7;
  EXPECT_FALSE(o.check().is_ok());
}

TEST(FrameGroup, BecomesAFringeSet) {
  FrameGroup g;
  g.images = {cv::Mat(4, 4, CV_8U, cv::Scalar(1)), cv::Mat(4, 4, CV_8U, cv::Scalar(2)),
              cv::Mat(4, 4, CV_8U, cv::Scalar(3))};
  g.index = 7;
  g.timestamp = milliseconds(5);
  const FringeSet s = to_fringe_set(g);
  EXPECT_TRUE(s.check().is_ok());
  EXPECT_EQ(s.images.size(), 3u);
  EXPECT_EQ(s.index, 7);
  EXPECT_EQ(s.timestamp, milliseconds(5));
}

TEST(SoftwareSyncStream, MatchesLiveAsTheBatchMatcherDoes) {
  for (const int offset_ms : {0, 3, 17}) {
    SoftwareScene scene = make_scene(5, 3, milliseconds(offset_ms));
    // Cycle 2 loses its pattern-1 frames (700..800 ms): that cycle is dropped, the others not.
    std::vector<CameraFrame> frames;
    for (const CameraFrame& f : scene.frames)
      if (f.timestamp < milliseconds(700) || f.timestamp >= milliseconds(800)) frames.push_back(f);
    SoftwareSyncOptions o;
    o.patterns_per_cycle = 3;
    SoftwareSyncStream stream(o);
    std::vector<FrameGroup> groups;
    size_t shown = 0;
    for (const CameraFrame& f : frames) {
      // The projector loop runs ahead of the camera: presentations up to this frame's time.
      while (shown < scene.shown.size() && scene.shown[shown].presented <= f.timestamp)
        stream.presented(scene.shown[shown++]);
      if (auto g = stream.push(f)) groups.push_back(*g);
    }
    // Cycle 4 has no next cycle to end it: still pending.
    ASSERT_EQ(groups.size(), 3u) << "offset " << offset_ms;
    EXPECT_EQ(groups[0].index, 0);
    EXPECT_EQ(groups[1].index, 1);
    EXPECT_EQ(groups[2].index, 3);
    for (const FrameGroup& g : groups)
      for (int k = 0; k < 3; ++k) EXPECT_EQ(value_of(g.images[k]), 200 + k);
    EXPECT_EQ(stream.counters().cycles_dropped, 1);
  }
}

// ---- tagged frames ----

CameraFrame tagged(int64_t sequence, int pattern) {
  CameraFrame f = frame_at(sequence, milliseconds(sequence), Timestamp(0),
                           static_cast<uint8_t>(100 + sequence));
  f.pattern = pattern;
  return f;
}

TEST(TaggedPatternSync, GroupsCompleteCyclesAndDropsBrokenOnes) {
  // 4 frames per cycle: a cue (untagged) and patterns 0..2.
  TaggedPatternSync sync({3, 4});
  std::vector<FrameGroup> groups;
  auto feed = [&](int64_t sequence) {
    const int position = static_cast<int>(sequence % 4);
    if (auto g = sync.push(tagged(sequence, position - 1))) groups.push_back(*g);
  };
  for (int64_t s = 0; s < 8; ++s) feed(s);  // cycles 0 and 1, complete
  for (int64_t s : {8, 9, 11}) feed(s);     // cycle 2 lacks pattern 1 (sequence 10 lost)
  for (int64_t s = 12; s < 16; ++s) feed(s);
  feed(16);
  feed(17);  // cycle 4 in progress when the stream ends
  sync.finish();
  ASSERT_EQ(groups.size(), 3u);
  EXPECT_EQ(groups[0].index, 0);
  EXPECT_EQ(groups[1].index, 1);
  EXPECT_EQ(groups[2].index, 3);  // the cycle number: dropped cycle 2 leaves a gap
  EXPECT_EQ(groups[2].sequences, std::vector<int64_t>({13, 14, 15}));
  EXPECT_EQ(value_of(groups[2].images[0]), 113);
  EXPECT_EQ(groups[2].timestamp, milliseconds(13));
  EXPECT_EQ(sync.counters().cycles_dropped, 2);
  ASSERT_EQ(sync.dropped().size(), 2u);
  EXPECT_TRUE(contains(sync.dropped()[0], "cycle 2: pattern 1 never arrived")) << sync.dropped()[0];
  EXPECT_TRUE(contains(sync.dropped()[1], "the stream ended")) << sync.dropped()[1];

  TaggedPatternSync twice({2, 2});
  EXPECT_FALSE(twice.push(tagged(0, 0)));
  EXPECT_FALSE(twice.push(tagged(1, 0)));  // pattern 0 again in cycle 0: never a wrong pair
  EXPECT_EQ(twice.counters().cycles_dropped, 1);
  EXPECT_TRUE(contains(twice.dropped().front(), "arrived twice"));
  EXPECT_FALSE(TaggedSyncOptions({3, 2}).check().is_ok());
}

}  // namespace
}  // namespace gvkit
