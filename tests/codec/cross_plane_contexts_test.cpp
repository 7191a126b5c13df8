// Cross-plane contexts (flags2 bit 4): the Y and Z planes start their contexts from the X plane's
// final context states. The decoder reproduces the encoder's reconstruction bit for bit (intra, P
// and B frames, with temporal contexts off so that P and B frames use them too; lossy in both
// presets with the other tools on, with shared motion, lossless and near-lossless); a Y plane
// like X costs fewer bits; on and off both write the bit as asked in every frame; bad flags2
// bits, missing X states and damaged segments are rejected with a message.
#include <random>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/cross_plane.hpp"
#include "gvkit/codec/cross_plane_contexts.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/plane_coding.hpp"
#include "packet_surgery.hpp"

namespace gvkit::codec {
namespace {

// The flags2 bits of every packet of a stream, or'ed, and whether every packet has `bit`.
uint8_t all_flags2(const std::string& stream, uint8_t bit, bool* every) {
  auto reader = GvidReader::open_memory(stream, "x.gvid");
  GVKIT_CHECK(reader.is_ok());
  uint8_t flags2 = 0;
  *every = true;
  for (int64_t f = 0; f < (*reader)->frame_count(); ++f) {
    auto h = (*reader)->packet_header(f);
    GVKIT_CHECK(h.is_ok());
    flags2 |= h->flags2;
    *every = *every && (h->flags2 & bit);
  }
  return flags2;
}

TEST(CrossPlaneContexts, EncoderReconstructionEqualsDecoderOutputBitExactly) {
  const auto frames = testing::make_moving_analytic_video(48, 6);
  const SequenceInfo info = testing::info_for(frames);
  struct Case {
    std::string name;
    EncoderOptions o;
  };
  std::vector<Case> cases;
  // The other tools at their defaults, but temporal contexts, which P and B frames would use
  // instead.
  for (const Preset preset : {Preset::kFast, Preset::kSlow})
    for (const int bframes : {0, 1}) {
      EncoderOptions o;
      o.temporal_contexts = false;
      o.qp = 6;
      o.preset = preset;
      o.bframes = bframes;
      o.intra_period = 4;
      o.cross_plane_contexts = true;
      cases.push_back(
          {std::string(preset_name(preset)) + (bframes ? ", B frames" : ", P frames"), o});
    }
  EncoderOptions shared;
  shared.temporal_contexts = false;
  shared.qp = 0;
  shared.preset = Preset::kSlow;
  shared.bframes = 0;
  shared.shared_motion = true;
  shared.threads = 3;
  shared.cross_plane_contexts = true;
  cases.push_back({"slow, shared motion, 3 threads", shared});
  EncoderOptions lossless;
  lossless.lossless = true;
  lossless.preset = Preset::kFast;
  lossless.cross_plane_contexts = true;
  lossless.temporal_contexts = false;
  cases.push_back({"lossless", lossless});
  EncoderOptions near = lossless;
  near.lossless = false;
  near.max_error_mm = 0.05;
  near.preset = Preset::kSlow;
  cases.push_back({"near-lossless, slow", near});
  EncoderOptions intra;
  intra.qp = -12;
  intra.intra_only = true;
  intra.preset = Preset::kSlow;
  intra.cross_plane_contexts = true;
  cases.push_back({"intra only, qp -12", intra});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string bytes = testing::writer_round_trip(frames, info, c.o);
    bool every = false;
    all_flags2(bytes, format::kFrame2CrossPlaneContexts, &every);
    EXPECT_TRUE(every);
  }
}

// Plane level: a Y plane like X (same structure, other values) costs fewer bits when it starts
// from X's final context states; the decoder needs the same states, and without them fails with
// a message.
TEST(CrossPlaneContexts, InheritedStatesCostLessAndNeedTheXPlane) {
  const auto ramp = [](uint32_t seed, int offset) {
    SamplePlane p;
    p.width = p.height = 64;
    p.samples.resize(64 * 64);
    std::mt19937 rng(seed);
    for (int y = 0; y < 64; ++y)
      for (int i = 0; i < 64; ++i)
        p.at(i, y) = static_cast<uint16_t>(offset + 40 * i + 25 * y + (i / 16 + y / 16) * 500 +
                                           rng() % (i < 32 ? 2000 : 20));
    return p;
  };
  const SamplePlane x = ramp(7, 20000), y = ramp(8, 15000);
  for (const bool lossless : {false, true})
    for (const bool rdo : {false, true}) {
      SCOPED_TRACE(std::string(lossless ? "lossless" : "qp' 30") + (rdo ? " slow" : " fast"));
      PlaneCodingParams p;
      p.qp_prime = 30;
      p.lossless = lossless;
      p.adaptive_levels = lossless;
      p.rdo = rdo;
      CrossPlaneContextStates x_states, decoded_states;
      CrossPlaneLinks x_links;
      x_links.contexts_out = &x_states;
      const PlaneEncodeResult ex = encode_plane(x, p, nullptr, nullptr, nullptr, nullptr, &x_links);
      ASSERT_FALSE(x_states.contexts.empty());
      CrossPlaneLinks y_links;
      y_links.contexts = &x_states;
      const PlaneEncodeResult ey = encode_plane(y, p, nullptr, nullptr, nullptr, nullptr, &y_links);
      const PlaneEncodeResult plain = encode_plane(y, p);
      EXPECT_LT(ey.bytes.size(), plain.bytes.size());
      CrossPlaneLinks dx_links;
      dx_links.contexts_out = &decoded_states;
      auto dx = decode_plane(ex.bytes, 64, 64, p, nullptr, nullptr, nullptr, nullptr, &dx_links);
      ASSERT_TRUE(dx.is_ok()) << dx.status().message();
      EXPECT_EQ(dx->samples, ex.reconstruction.samples);
      ASSERT_EQ(decoded_states.contexts.size(), x_states.contexts.size());
      for (size_t i = 0; i < x_states.contexts.size(); ++i) {
        EXPECT_EQ(decoded_states.contexts[i].state, x_states.contexts[i].state) << i;
        EXPECT_EQ(decoded_states.contexts[i].mps, x_states.contexts[i].mps) << i;
      }
      CrossPlaneLinks dy_links;
      dy_links.contexts = &decoded_states;
      auto dy = decode_plane(ey.bytes, 64, 64, p, nullptr, nullptr, nullptr, nullptr, &dy_links);
      ASSERT_TRUE(dy.is_ok()) << dy.status().message();
      EXPECT_EQ(dy->samples, ey.reconstruction.samples);
      if (lossless) {
        EXPECT_EQ(dy->samples, y.samples);
      }
      // States not recorded by a plane.
      CrossPlaneContextStates empty;
      dy_links.contexts = &empty;
      auto bad = decode_plane(ey.bytes, 64, 64, p, nullptr, nullptr, nullptr, nullptr, &dy_links);
      ASSERT_FALSE(bad.is_ok());
      EXPECT_NE(bad.status().message().find("cross-plane contexts"), std::string::npos)
          << bad.status().message();
    }
}

TEST(CrossPlaneContexts, OffAndOnSignalTheToolInEveryFrame) {
  const auto frames = testing::make_moving_analytic_video(48, 5);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.qp = 0;
  o.preset = Preset::kFast;
  o.bframes = 1;
  o.temporal_contexts = false;
  EXPECT_TRUE(EncoderOptions{}.cross_plane_contexts);  // on by default (docs/benchmarks.md)
  o.cross_plane_contexts = false;
  auto off = encode_gvid(frames, info, o);
  ASSERT_TRUE(off.is_ok());
  bool every = true;
  EXPECT_FALSE(all_flags2(*off, format::kFrame2CrossPlaneContexts, &every) &
               format::kFrame2CrossPlaneContexts);
  o.cross_plane_contexts = true;
  auto on = encode_gvid(frames, info, o);
  ASSERT_TRUE(on.is_ok());
  const uint8_t flags2 = all_flags2(*on, format::kFrame2CrossPlaneContexts, &every);
  EXPECT_TRUE(every);
  EXPECT_TRUE(flags2 & format::kFrame2CrossPlane);
  EXPECT_FALSE(*on == *off);
}

TEST(CrossPlaneContexts, BadSyntaxIsRejectedWithAMessage) {
  const auto frames = testing::make_moving_analytic_video(32, 1);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.qp = 0;
  o.preset = Preset::kFast;
  o.intra_only = true;
  o.max_transform = 4;
  o.deblocking = false;
  o.cross_plane = false;  // flags2 then holds the cross-plane contexts bit alone
  o.cross_plane_contexts = true;
  auto stream = encode_gvid(frames, info, o);
  ASSERT_TRUE(stream.is_ok());
  auto reader = GvidReader::open_memory(*stream, "x.gvid");
  ASSERT_TRUE(reader.is_ok());
  const std::string packet =
      testing::first_packet(*stream, static_cast<size_t>((*reader)->header_bytes()));
  ASSERT_TRUE(decode_frame_packet(packet, info, 0).is_ok());
  // Flags2 bit 7 (temporal contexts) in this intra frame is rejected (32 is inter partitions,
  // partition_test; 64 the deblocking filter, deblocking_test).
  for (const uint8_t bits : {128}) {
    auto d = decode_frame_packet(
        testing::with_flags2(packet, format::kFrame2CrossPlaneContexts | bits), info, 0);
    ASSERT_FALSE(d.is_ok());
    EXPECT_NE(d.status().message().find("temporal contexts in an intra frame"), std::string::npos)
        << d.status().message();
  }
  // Random damage in the payload (CRC fixed up, so that it reaches the macroblock layer): a
  // Status naming the plane, never a crash (ASan runs this too).
  std::mt19937 rng(11);
  int failures = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const std::string p = testing::damage_payload(packet, rng, 1 + trial % 4, 8);
    auto d = decode_frame_packet(p, info, 0);
    if (!d.is_ok()) {
      ++failures;
      EXPECT_NE(d.status().message().find("plane"), std::string::npos) << d.status().message();
    }
  }
  EXPECT_GT(failures, 0);
  // Without the bit, Y and Z are read with other contexts: rejected, or other samples.
  auto right = decode_frame_packet(packet, info, 0);
  auto cleared = decode_frame_packet(testing::with_flags2(packet, 0), info, 0);
  ASSERT_TRUE(right.is_ok());
  EXPECT_TRUE(!cleared.is_ok() || !testing::same_samples(cleared->xyz_mm, right->xyz_mm));
}

}  // namespace
}  // namespace gvkit::codec
