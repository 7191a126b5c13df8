// TD16 (the payload's first byte bit 6, docs/bitstream.md 4.15): the decoder
// reproduces the encoder in every configuration that has P frames (presets, B frames, several
// references, shared motion, lossless, near-lossless, threads), TD16 macroblocks are coded and
// make the ICT face's stream cheaper, off no packet has the flag, and the flag
// outside a P frame with TD prediction is rejected.
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/coding_stats.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "packet_surgery.hpp"
#include "support/test_support.hpp"

namespace gvkit::codec {
namespace {

// TD16 macroblocks over the frames of a coded sequence.
int64_t td16_macroblocks(const std::vector<FrameCodingStats>& stats) {
  int64_t n = 0;
  for (const FrameCodingStats& f : stats)
    for (const PlaneCodingStats& p : f.planes) n += p.td16_mbs;
  return n;
}

TEST(Td16, DecoderReproducesTheEncoderInEveryConfiguration) {
  const auto frames = testing::make_moving_analytic_video(64, 7);
  const SequenceInfo info = testing::info_for(frames);
  auto cases = testing::p_frame_cases();
  EncoderOptions no_merge = cases[4].second;  // slow, no B frames, QP 0
  no_merge.merge = false;
  cases.push_back({"slow without merge", no_merge});
  int64_t total = 0;
  for (const auto& [what, o] : cases) {
    SCOPED_TRACE(what);
    ASSERT_TRUE(o.td16);  // on by default
    std::vector<FrameCodingStats> stats;
    const std::string stream = testing::writer_round_trip(frames, info, o, &stats);
    for (const auto& [type, flags] : testing::payload_flags(stream))
      EXPECT_EQ((flags & format::kPayloadTd16) != 0, type == format::FrameType::kPredicted);
    total += td16_macroblocks(stats);
  }
  EXPECT_GT(total, 0);  // the mode is taken
}

// The ICT face (when the shared data is present), fast preset: the stream with TD16 is smaller
// and its geometry PSNR no more than 0.05 dB lower; off, no packet has the flag.
TEST(Td16, MakesTheIctFaceCheaper) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  testing::GeometryVideoOptions vo;
  vo.size = 128;
  vo.frames = 9;
  auto frames = testing::make_ict_face_video(data / "ict-facekit", vo);
  ASSERT_TRUE(frames.is_ok()) << frames.status().message();
  const SequenceInfo info = testing::info_for(*frames);
  EncoderOptions on;
  on.preset = Preset::kFast;
  on.qp = 0;
  EncoderOptions off = on;
  off.td16 = false;
  std::vector<FrameCodingStats> on_stats, off_stats;
  const std::string a = testing::writer_round_trip(*frames, info, on, &on_stats);
  const std::string b = testing::writer_round_trip(*frames, info, off, &off_stats);
  EXPECT_GT(td16_macroblocks(on_stats), 0);
  EXPECT_EQ(td16_macroblocks(off_stats), 0);
  EXPECT_LT(a.size(), b.size());
  EXPECT_GT(testing::stream_psnr_db(*frames, info, a),
            testing::stream_psnr_db(*frames, info, b) - 0.05);
  for (const auto& [type, flags] : testing::payload_flags(b))
    EXPECT_EQ(flags & format::kPayloadTd16, 0);
}

TEST(Td16, FlagOutsideAPFrameWithTdPredictionIsRejected) {
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
  EncoderOptions no_td = o;
  no_td.td_prediction = false;
  auto p2_no_td = encode_frame(frames[2], info, no_td, 2, &i0->planes);
  ASSERT_TRUE(p2_no_td.is_ok());
  const auto with_flag = [](const std::string& packet) {
    std::string payload = testing::packet_payload(packet);
    EXPECT_EQ(payload[0] & format::kPayloadTd16, 0);
    payload[0] = static_cast<char>(payload[0] | format::kPayloadTd16);
    return testing::with_payload(packet, payload);
  };
  const auto expect_rejected = [](const Result<GeometryImage>& r) {
    ASSERT_FALSE(r.is_ok());
    EXPECT_NE(r.status().message().find("TD16 outside a P frame with TD prediction"),
              std::string::npos)
        << r.status().message();
  };
  expect_rejected(decode_frame_packet(with_flag(i0->packet), info, 0));
  expect_rejected(
      decode_frame_packet(with_flag(b1->packet), info, 1, &i0->planes, nullptr, &p2->planes));
  expect_rejected(decode_frame_packet(with_flag(p2_no_td->packet), info, 2, &i0->planes));
  // The P frame with TD prediction carries it and decodes.
  EXPECT_NE(testing::packet_payload(p2->packet)[0] & format::kPayloadTd16, 0);
  EXPECT_TRUE(decode_frame_packet(p2->packet, info, 2, &i0->planes).is_ok());
}

}  // namespace
}  // namespace gvkit::codec
