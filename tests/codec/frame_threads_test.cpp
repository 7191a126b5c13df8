// Frame-level threads of SequenceEncoder: with options.threads > 1 the B frames between two
// anchors are coded on a thread of their own while the next anchors are coded. The stream must
// be the same byte for byte as with one thread, in every configuration that uses B frames, and
// the frames must leave in decode order (each anchor, then the B frames before it). Within a
// frame, the planes are coded in parallel where they do not depend on each other.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "geometry_video_material.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/sequence_encoder.hpp"

namespace gvkit::codec {
namespace {

SequenceInfo info_for(const std::vector<GeometryImage>& frames) {
  auto info = make_sequence_info(frames, 16, 30.0);
  GVKIT_CHECK(info.is_ok(), info.status().message());
  return std::move(info).value();
}

std::vector<GeometryImage> video(int size, int frames) {
  testing::GeometryVideoOptions o;
  o.size = size;
  o.frames = frames;
  return testing::make_analytic_video(o);
}

// Every frame SequenceEncoder gives back, in the order it gives them, pushing then flushing.
std::vector<SequenceFrame> encode_all(const std::vector<GeometryImage>& frames,
                                      const SequenceInfo& info, const EncoderOptions& o) {
  auto encoder = SequenceEncoder::create(info, o);
  GVKIT_CHECK(encoder.is_ok(), encoder.status().message());
  std::vector<SequenceFrame> out;
  for (const GeometryImage& f : frames) {
    auto done = (*encoder)->push(f);
    GVKIT_CHECK(done.is_ok(), done.status().message());
    for (auto& d : *done) out.push_back(std::move(d));
  }
  auto rest = (*encoder)->flush();
  GVKIT_CHECK(rest.is_ok(), rest.status().message());
  for (auto& d : *rest) out.push_back(std::move(d));
  return out;
}

TEST(FrameThreads, TwoAndFourThreadsWriteTheSameStreamAsOne) {
  const auto frames = video(48, 11);
  const SequenceInfo info = info_for(frames);
  struct Case {
    const char* name;
    EncoderOptions o;
  };
  std::vector<Case> cases;
  for (const Preset preset : {Preset::kFast, Preset::kSlow})
    for (const int b : {1, 2}) {
      EncoderOptions o;
      o.preset = preset;
      o.qp = 6;
      o.bframes = b;
      o.intra_period = 8;  // an I frame inside the sequence: the reference list restarts
      cases.push_back({preset == Preset::kFast ? "fast" : "slow", o});
    }
  EncoderOptions half;
  half.qp = 18;
  half.resolution = Resolution::kHalf;
  cases.push_back({"half resolution", half});
  EncoderOptions lossless;
  lossless.lossless = true;
  lossless.bframes = 1;
  lossless.preset = Preset::kFast;
  cases.push_back({"lossless with B frames", lossless});
  for (const Case& c : cases) {
    const auto one = encode_gvid(frames, info, c.o);
    ASSERT_TRUE(one.is_ok()) << c.name << ": " << one.status().message();
    for (const int threads : {2, 4}) {
      EncoderOptions o = c.o;
      o.threads = threads;
      const auto many = encode_gvid(frames, info, o);
      ASSERT_TRUE(many.is_ok()) << c.name;
      EXPECT_EQ(*one, *many) << c.name << ", " << threads << " threads";
    }
    // The stream decodes, every frame.
    auto reader = GvidReader::open_memory(*one, "threads.gvid");
    ASSERT_TRUE(reader.is_ok()) << reader.status().message();
    ASSERT_EQ((*reader)->frame_count(), static_cast<int64_t>(frames.size())) << c.name;
    for (int64_t f = 0; f < (*reader)->frame_count(); ++f)
      EXPECT_TRUE((*reader)->decode_frame(f).is_ok()) << c.name << ", frame " << f;
  }
}

// With a texture plane (coded beside X, which it takes nothing from), at both presets.
TEST(FrameThreads, TexturedFramesWriteTheSameStreamWithAnyThreads) {
  auto frames = video(48, 9);
  for (size_t f = 0; f < frames.size(); ++f) {
    cv::Mat t(frames[f].xyz_mm.size(), CV_32F);
    for (int y = 0; y < t.rows; ++y)
      for (int x = 0; x < t.cols; ++x)
        t.at<float>(y, x) =
            static_cast<float>((x * 7 + y * 3 + 11 * static_cast<int>(f)) % 97) / 96.f;
    frames[f].texture = t;
  }
  const SequenceInfo info = info_for(frames);
  ASSERT_TRUE(info.has_texture);
  for (const Preset preset : {Preset::kFast, Preset::kSlow}) {
    EncoderOptions o;
    o.preset = preset;
    o.qp = 6;
    o.bframes = 1;
    const auto one = encode_gvid(frames, info, o);
    ASSERT_TRUE(one.is_ok()) << one.status().message();
    for (const int threads : {2, 4}) {
      o.threads = threads;
      const auto many = encode_gvid(frames, info, o);
      ASSERT_TRUE(many.is_ok());
      EXPECT_EQ(*one, *many) << preset_name(preset) << ", " << threads << " threads";
    }
  }
}

TEST(FrameThreads, FramesLeaveInDecodeOrderWithTheSamePackets) {
  const auto frames = video(32, 12);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.qp = 6;
  o.bframes = 2;
  o.preset = Preset::kFast;
  const std::vector<SequenceFrame> one = encode_all(frames, info, o);
  o.threads = 2;
  const std::vector<SequenceFrame> two = encode_all(frames, info, o);
  ASSERT_EQ(one.size(), frames.size());
  ASSERT_EQ(two.size(), frames.size());
  for (size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].number, two[i].number) << "position " << i;
    EXPECT_EQ(one[i].type, two[i].type) << "position " << i;
    EXPECT_EQ(one[i].packet, two[i].packet) << "frame " << one[i].number;
  }
  // Decode order: 0 (I), 3 (P), 1, 2 (B), 6 (P), 4, 5 (B), 9 (P), 7, 8 (B), then the frames
  // after the last anchor as P frames, 10 and 11 (10 is coded while 7 and 8 still are, and
  // leaves after them).
  const uint32_t expected[] = {0, 3, 1, 2, 6, 4, 5, 9, 7, 8, 10, 11};
  for (size_t i = 0; i < two.size(); ++i) EXPECT_EQ(two[i].number, expected[i]) << i;
}

// A B-frame candidate that fails only when it is coded (a non-finite domain pixel): with one
// thread the push of the anchor after it reports the failure; with background B frames a later
// push or flush() does, naming the frame, and the encoder still ends cleanly.
TEST(FrameThreads, ABackgroundBFrameFailureReachesTheCaller) {
  auto frames = video(32, 12);
  const cv::Point inside = [&] {
    for (int y = 0; y < frames[4].domain_mask.rows; ++y)
      for (int x = 0; x < frames[4].domain_mask.cols; ++x)
        if (frames[4].domain_mask.at<uint8_t>(y, x)) return cv::Point(x, y);
    return cv::Point(-1, -1);
  }();
  ASSERT_GE(inside.x, 0);
  const SequenceInfo info = info_for(frames);
  frames[4].xyz_mm.at<cv::Vec3f>(inside)[1] = std::numeric_limits<float>::quiet_NaN();
  for (const int threads : {1, 2}) {
    EncoderOptions o;
    o.qp = 6;
    o.bframes = 2;  // anchors 0, 3, 6, 9; frames 4 and 5 are B frames
    o.preset = Preset::kFast;
    o.threads = threads;
    auto encoder = SequenceEncoder::create(info, o);
    ASSERT_TRUE(encoder.is_ok());
    Status failure = Status::ok();
    size_t failed_at = frames.size();
    for (size_t i = 0; i < frames.size() && failure.is_ok(); ++i) {
      auto done = (*encoder)->push(frames[i]);
      if (!done.is_ok()) failure = done.status(), failed_at = i;
    }
    if (failure.is_ok()) {
      auto rest = (*encoder)->flush();
      if (!rest.is_ok()) failure = rest.status();
    }
    ASSERT_FALSE(failure.is_ok()) << threads << " threads";
    EXPECT_NE(failure.message().find("frame 4"), std::string::npos) << failure.message();
    if (threads == 1) {
      EXPECT_EQ(failed_at, 6u);
    }
  }
}

TEST(FrameThreads, RateControlKeepsOneFrameAtATime) {
  // A bitrate sets each frame's QP from the bits of the frames before it: the frames stay in
  // sequence (the planes of a frame may still run in parallel) and the stream is the same.
  const auto frames = video(32, 9);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.preset = Preset::kFast;
  o.bitrate_kbps = 200;
  const auto one = encode_gvid(frames, info, o);
  o.threads = 2;
  const auto two = encode_gvid(frames, info, o);
  ASSERT_TRUE(one.is_ok() && two.is_ok());
  EXPECT_EQ(*one, *two);
}

}  // namespace
}  // namespace gvkit::codec
