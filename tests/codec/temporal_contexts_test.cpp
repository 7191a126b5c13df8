// Temporal contexts (flags2 bit 7, docs/bitstream.md 4.13): the decoder reproduces the encoder
// bit for bit in every configuration, through GvidReader in any order of access; every P and B
// packet carries the bit and no I packet does; P and B frames spend fewer bits on macroblock
// types; and packets that ask for the tool in an intra frame, next to cross-plane contexts, or
// from a reference without context states are rejected.
#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/coding_stats.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "packet_surgery.hpp"

namespace gvkit::codec {
namespace {

// Whether each packet (display order) has flags2 bit 7.
void expect_temporal_in_inter_frames(const std::string& stream) {
  auto reader = GvidReader::open_memory(stream, "x.gvid").value();
  int inter = 0;
  for (int64_t f = 0; f < reader->frame_count(); ++f) {
    const uint8_t flags2 = reader->packet_header(f)->flags2;
    const bool intra = reader->frame_type(f) == format::FrameType::kIntra;
    EXPECT_EQ((flags2 & format::kFrame2TemporalContexts) != 0, !intra) << "frame " << f;
    if (!intra) {
      ++inter;
      EXPECT_EQ(flags2 & format::kFrame2CrossPlaneContexts, 0) << "frame " << f;
    }
  }
  EXPECT_GT(inter, 0);
}

TEST(TemporalContexts, DecoderReproducesTheEncoderInEveryConfiguration) {
  const auto frames = testing::make_moving_analytic_video(48, 7);
  const SequenceInfo info = testing::info_for(frames);
  std::vector<std::pair<std::string, EncoderOptions>> cases;
  for (const Preset preset : {Preset::kFast, Preset::kSlow})
    for (const int bframes : {0, 2}) {
      EncoderOptions o;
      o.qp = 6;
      o.preset = preset;
      o.bframes = bframes;
      o.intra_period = 5;  // a second I frame restarts from the initial states
      o.threads = 2;
      cases.push_back(
          {std::string(preset_name(preset)) + " bframes " + std::to_string(bframes), o});
    }
  EncoderOptions lossless;
  lossless.lossless = true;
  lossless.preset = Preset::kFast;
  cases.push_back({"lossless", lossless});
  EncoderOptions near = lossless;
  near.lossless = false;
  near.max_error_mm = 0.05;
  near.shared_motion = true;
  cases.push_back({"near-lossless, shared motion", near});
  EncoderOptions one_ref;
  one_ref.qp = 18;
  one_ref.refs = 1;
  one_ref.value_prediction = ValuePrediction::kAffine;
  cases.push_back({"one reference, affine value prediction", one_ref});
  for (const auto& [name, o] : cases) {
    SCOPED_TRACE(name);
    expect_temporal_in_inter_frames(testing::writer_round_trip(frames, info, o));
  }
}

TEST(TemporalContexts, RandomAccessDecodesTheSameFrames) {
  const auto frames = testing::make_moving_analytic_video(32, 9);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.qp = 6;
  o.intra_period = 4;
  const std::string stream = encode_gvid(frames, info, o).value();
  auto sequential = GvidReader::open_memory(stream, "x.gvid").value();
  std::vector<GeometryImage> in_order;
  for (int64_t f = 0; f < sequential->frame_count(); ++f)
    in_order.push_back(sequential->decode_frame(f).value());
  // A fresh reader, frames out of order: each anchor chain is decoded again from its I frame.
  auto reader = GvidReader::open_memory(stream, "x.gvid").value();
  for (const int64_t f : {7, 2, 8, 0, 5, 3, 6, 1, 4}) {
    SCOPED_TRACE("frame " + std::to_string(f));
    const GeometryImage image = reader->decode_frame(f).value();
    EXPECT_TRUE(testing::same_samples(image.xyz_mm, in_order[f].xyz_mm));
  }
}

TEST(TemporalContexts, InterFramesSpendFewerBitsOnMacroblockTypes) {
  // What the inherited states know best is how often the frame's macroblocks skip: the skip and
  // type flags of P and B frames cost less than when every plane learns them from p = 0.5 (or
  // from the X plane's states) again.
  const auto frames = testing::make_moving_analytic_video(160, 6);
  const SequenceInfo info = testing::info_for(frames);
  for (const Preset preset : {Preset::kFast, Preset::kSlow})
    for (const int qp : {0, 12}) {
      SCOPED_TRACE(std::string(preset_name(preset)) + " qp " + std::to_string(qp));
      EncoderOptions on;
      on.qp = qp;
      on.preset = preset;
      // Plain SSD decisions: the outline weight moves which macroblocks skip at this small
      // video's outline, which its few hundred type bits at QP 12 are sensitive to.
      on.outline_weight = 1;
      EncoderOptions off = on;
      off.temporal_contexts = false;
      double type_bits[2] = {0, 0}, inter_planes[2] = {0, 0};
      for (const bool temporal : {false, true}) {
        std::vector<FrameCodingStats> stats;
        const std::string stream = encode_gvid(frames, info, temporal ? on : off, &stats).value();
        for (const FrameCodingStats& f : stats)
          if (!f.intra)
            for (const PlaneCodingStats& p : f.planes) {
              type_bits[temporal] += p.bits[kSyntaxMbType];
              inter_planes[temporal] += 1;
            }
      }
      EXPECT_EQ(inter_planes[0], inter_planes[1]);
      EXPECT_LT(type_bits[1], 0.97 * type_bits[0]);  // 4-21 % less on this video
    }
}

TEST(TemporalContexts, RejectsTheFlagWhereItCannotApply) {
  const auto frames = testing::make_moving_analytic_video(32, 2);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.bframes = 0;
  auto i0 = encode_frame(frames[0], info, o, 0);
  ASSERT_TRUE(i0.is_ok());
  auto p1 = encode_frame(frames[1], info, o, 1, &i0->planes);
  ASSERT_TRUE(p1.is_ok());
  const auto flags2 = [](const std::string& packet) {
    return format::read_packet_header(packet).value().flags2;
  };
  ASSERT_NE(flags2(p1->packet) & format::kFrame2TemporalContexts, 0);
  ASSERT_EQ(flags2(i0->packet) & format::kFrame2TemporalContexts, 0);
  EXPECT_TRUE(decode_frame_packet(p1->packet, info, 1, &i0->planes).is_ok());
  const auto expect_rejected = [&](const std::string& packet, const std::vector<SamplePlane>* ref,
                                   const std::string& what) {
    auto r = decode_frame_packet(packet, info, ref ? 1 : 0, ref);
    ASSERT_FALSE(r.is_ok()) << what;
    EXPECT_NE(r.status().message().find(what), std::string::npos) << r.status().message();
  };
  expect_rejected(
      testing::with_flags2(i0->packet, flags2(i0->packet) | format::kFrame2TemporalContexts),
      nullptr, "temporal contexts in an intra frame");
  expect_rejected(
      testing::with_flags2(p1->packet, flags2(p1->packet) | format::kFrame2CrossPlaneContexts),
      &i0->planes, "temporal contexts with cross-plane contexts");
  // A reference that was not reconstructed from a segment carries no context states.
  std::vector<SamplePlane> bare = i0->planes;
  for (SamplePlane& p : bare) p.final_contexts.reset();
  expect_rejected(p1->packet, &bare, "carry no final context states");
  // The encoder then codes the P frame without the tool.
  auto plain = encode_frame(frames[1], info, o, 1, &bare);
  ASSERT_TRUE(plain.is_ok());
  EXPECT_EQ(flags2(plain->packet) & format::kFrame2TemporalContexts, 0);
  EXPECT_TRUE(decode_frame_packet(plain->packet, info, 1, &bare).is_ok());
}

}  // namespace
}  // namespace gvkit::codec
