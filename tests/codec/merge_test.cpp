// Merge (the payload's first byte bit 5, docs/bitstream.md 4.14): the decoder
// reproduces the encoder in every configuration that has P frames (presets, B frames, several
// references, partitions, shared motion, lossless, near-lossless, threads), skips and
// macroblocks with a residual take neighbours' vectors and make the stream smaller, off no
// packet has the flag, and the flag outside a P frame is rejected.
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/coding_stats.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "packet_surgery.hpp"
#include "support/test_support.hpp"

namespace gvkit::codec {
namespace {

// Skips (merged = false) or other macroblocks (true) at a neighbour's vector, over the P frames
// of a coded sequence.
int64_t merges(const std::vector<FrameCodingStats>& stats, bool merged = false) {
  int64_t n = 0;
  for (const FrameCodingStats& f : stats)
    for (const PlaneCodingStats& p : f.planes) n += merged ? p.merged_mbs : p.merge_skip_mbs;
  return n;
}

TEST(Merge, DecoderReproducesTheEncoderInEveryConfiguration) {
  const auto frames = testing::make_moving_analytic_video(64, 7);
  const SequenceInfo info = testing::info_for(frames);
  const auto cases = testing::p_frame_cases();
  int64_t total = 0;
  for (const auto& [what, o] : cases) {
    SCOPED_TRACE(what);
    ASSERT_TRUE(o.merge);  // on by default
    std::vector<FrameCodingStats> stats;
    const std::string stream = testing::writer_round_trip(frames, info, o, &stats);
    for (const auto& [type, flags] : testing::payload_flags(stream))
      EXPECT_EQ((flags & format::kPayloadMerge) != 0, type == format::FrameType::kPredicted);
    total += merges(stats) + merges(stats, true);
  }
  EXPECT_GT(total, 0);  // the candidates are taken
}

// The ICT face (when the shared data is present): at a low rate, where most macroblocks skip,
// merge makes the slow preset's stream smaller at about the same error.
TEST(Merge, NeighboursVectorsMakeTheIctFaceSmaller) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  testing::GeometryVideoOptions vo;
  vo.size = 128;
  vo.frames = 9;
  auto frames = testing::make_ict_face_video(data / "ict-facekit", vo);
  ASSERT_TRUE(frames.is_ok()) << frames.status().message();
  const SequenceInfo info = testing::info_for(*frames);
  EncoderOptions on;
  on.preset = Preset::kSlow;
  on.qp = 12;
  EncoderOptions off = on;
  off.merge = false;
  std::vector<FrameCodingStats> on_stats, off_stats;
  const std::string a = testing::writer_round_trip(*frames, info, on, &on_stats);
  const std::string b = testing::writer_round_trip(*frames, info, off, &off_stats);
  EXPECT_GT(merges(on_stats), 0);
  EXPECT_GT(merges(on_stats, true), 0);
  EXPECT_EQ(merges(off_stats) + merges(off_stats, true), 0);
  EXPECT_LT(a.size(), b.size());
  for (const auto& [type, flags] : testing::payload_flags(b))
    EXPECT_EQ(flags & format::kPayloadMerge, 0);
}

TEST(Merge, FlagOutsideAPFrameIsRejected) {
  const auto frames = testing::make_moving_analytic_video(32, 3);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.bframes = 1;
  auto i0 = encode_frame(frames[0], info, o, 0);
  ASSERT_TRUE(i0.is_ok());
  auto p2 = encode_frame(frames[2], info, o, 2, &i0->planes);
  ASSERT_TRUE(p2.is_ok());
  auto b1 = encode_frame(frames[1], info, o, 1, &i0->planes, &p2->planes);
  ASSERT_TRUE(b1.is_ok());
  const auto with_flag = [](const std::string& packet) {
    std::string payload = testing::packet_payload(packet);
    EXPECT_EQ(payload[0] & format::kPayloadMerge, 0);
    payload[0] = static_cast<char>(payload[0] | format::kPayloadMerge);
    return testing::with_payload(packet, payload);
  };
  const auto expect_rejected = [](const Result<GeometryImage>& r) {
    ASSERT_FALSE(r.is_ok());
    EXPECT_NE(r.status().message().find("merge outside a P frame"), std::string::npos)
        << r.status().message();
  };
  expect_rejected(decode_frame_packet(with_flag(i0->packet), info, 0));
  expect_rejected(
      decode_frame_packet(with_flag(b1->packet), info, 1, &i0->planes, nullptr, &p2->planes));
  // The P frame carries it and decodes.
  EXPECT_NE(testing::packet_payload(p2->packet)[0] & format::kPayloadMerge, 0);
  EXPECT_TRUE(decode_frame_packet(p2->packet, info, 2, &i0->planes).is_ok());
}

// The co-located candidate comes from the reference's motion record, which only planes that
// encode_frame or decode_frame_packet reconstructed carry: the decoder refuses a merge frame
// against bare planes instead of decoding it wrongly, and the encoder codes one without merge.
TEST(Merge, NeedsTheReferenceAsTheCodecReconstructedIt) {
  const auto frames = testing::make_moving_analytic_video(48, 3);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.bframes = 0;
  o.refs = 1;
  o.temporal_contexts = false;  // (which need the reference's context states as well)
  auto i0 = encode_frame(frames[0], info, o, 0);
  ASSERT_TRUE(i0.is_ok());
  auto p1 = encode_frame(frames[1], info, o, 1, &i0->planes);
  ASSERT_TRUE(p1.is_ok());
  for (const SamplePlane& p : p1->planes) EXPECT_NE(p.motion, nullptr);  // a P frame's record
  for (const SamplePlane& p : i0->planes) EXPECT_EQ(p.motion, nullptr);
  auto p2 = encode_frame(frames[2], info, o, 2, &p1->planes);
  ASSERT_TRUE(p2.is_ok());
  ASSERT_NE(testing::packet_payload(p2->packet)[0] & format::kPayloadMerge, 0);
  std::vector<SamplePlane> decoded;
  ASSERT_TRUE(decode_frame_packet(p1->packet, info, 1, &i0->planes, &decoded).is_ok());
  for (const SamplePlane& p : decoded) EXPECT_NE(p.motion, nullptr);
  EXPECT_TRUE(decode_frame_packet(p2->packet, info, 2, &decoded).is_ok());
  std::vector<SamplePlane> bare = decoded;
  for (SamplePlane& p : bare) {
    p.final_contexts.reset();
    p.motion.reset();
  }
  auto refused = decode_frame_packet(p2->packet, info, 2, &bare);
  ASSERT_FALSE(refused.is_ok());
  EXPECT_NE(refused.status().message().find("carry no motion record"), std::string::npos)
      << refused.status().message();
  auto plain = encode_frame(frames[2], info, o, 2, &bare);
  ASSERT_TRUE(plain.is_ok());
  EXPECT_EQ(testing::packet_payload(plain->packet)[0] & format::kPayloadMerge, 0);
  EXPECT_TRUE(decode_frame_packet(plain->packet, info, 2, &bare).is_ok());
}

}  // namespace
}  // namespace gvkit::codec
