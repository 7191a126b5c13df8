// Cross-plane residual prediction (flags2 bit 3): the Y and Z planes add a scaled copy of the X
// plane's residual per macroblock. The decoder reproduces the encoder's reconstruction bit for
// bit (intra, P and B frames; lossy in both presets, lossless and near-lossless, with and without
// threads); where Y's residual is a multiple of X's the tool removes most of Y's rate; lossless
// stays exact and near-lossless keeps its bound; off, no packet has the bit, on, every packet;
// bad scale syntax, flags2 bits and damaged segments are rejected with a message; with several
// references and 8x8 / 16x16 transforms on too, the round trip stays bit exact.
#include <random>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/cross_plane.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/plane_coding.hpp"
#include "packet_surgery.hpp"

namespace gvkit::codec {
namespace {

// A 64x64 plane: a smooth ramp plus noise (so that every macroblock codes a residual).
SamplePlane noisy_plane(uint32_t seed) {
  SamplePlane p;
  p.width = p.height = 64;
  p.samples.resize(64 * 64);
  std::mt19937 rng(seed);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      p.at(x, y) = static_cast<uint16_t>(20000 + 40 * x + 25 * y + rng() % 200);
  return p;
}

// y = x / 2 + 7000 sample by sample: Y's residual is about half of X's.
SamplePlane half_of(const SamplePlane& x) {
  SamplePlane y = x;
  for (auto& v : y.samples) v = static_cast<uint16_t>(v / 2 + 7000);
  return y;
}

int64_t scales_coded(const PlaneCodingStats& s, bool nonzero_only) {
  int64_t n = 0;
  for (int i = 0; i < kCrossScaleCount; ++i)
    if (!nonzero_only || kCrossScales[i] != 0) n += s.cross_scale_mbs[i];
  return n;
}

TEST(CrossPlane, ScaleBinarizationAndTermFollowTheSpecification) {
  EXPECT_EQ(cross_scale_index(-8), 0);
  EXPECT_EQ(cross_scale_index(0), 4);
  EXPECT_EQ(cross_scale_index(8), 8);
  EXPECT_EQ(cross_scale_index(3), -1);
  // (alpha r) >> 3 with an arithmetic shift: rounds towards minus infinity.
  EXPECT_EQ(cross_plane_term(1, 7), 0);
  EXPECT_EQ(cross_plane_term(1, -7), -1);
  EXPECT_EQ(cross_plane_term(-2, 12), -3);
  EXPECT_EQ(cross_plane_term(8, -65535), -65535);
  EXPECT_EQ(cross_plane_term(4, 65535 * 9), 65535 * 9 / 2);
  // The least-squares scale of a residual that is half the source's is 4 (eighths).
  CrossPlaneResidual source;
  source.reset(16, 16);
  int32_t r[256];
  for (int i = 0; i < 256; ++i) {
    source.samples[i] = (i * 37) % 101 - 50;
    r[i] = source.samples[i] / 2;
  }
  EXPECT_EQ(least_squares_cross_scale(r, source, 0, 0), 4);
  for (int i = 0; i < 256; ++i) r[i] = -source.samples[i];
  EXPECT_EQ(least_squares_cross_scale(r, source, 0, 0), -8);
  std::fill(source.samples.begin(), source.samples.end(), 0);
  EXPECT_EQ(least_squares_cross_scale(r, source, 0, 0), 0);
}

TEST(CrossPlane, CorrelatedPlaneCostsLessAndDecodesExactly) {
  const SamplePlane x = noisy_plane(1), y = half_of(x);
  for (const bool lossless : {true, false})
    for (const bool rdo : {false, true}) {
      SCOPED_TRACE(std::string(lossless ? "lossless" : "qp 0") + (rdo ? " slow" : " fast"));
      PlaneCodingParams p;
      p.lossless = lossless;
      p.adaptive_levels = lossless;
      p.qp_prime = 30;
      p.rdo = rdo;
      CrossPlaneResidual x_residual, decoded_x_residual;
      CrossPlaneLinks x_links{nullptr, &x_residual};
      const PlaneEncodeResult ex = encode_plane(x, p, nullptr, nullptr, nullptr, nullptr, &x_links);
      int nonzero_mbs = 0;
      for (uint8_t n : x_residual.mb_nonzero) nonzero_mbs += n;
      EXPECT_EQ(nonzero_mbs, 16);
      CrossPlaneLinks y_links{&x_residual, nullptr};
      const PlaneEncodeResult ey = encode_plane(y, p, nullptr, nullptr, nullptr, nullptr, &y_links);
      const PlaneEncodeResult plain = encode_plane(y, p);
      const auto ssd = [&](const SamplePlane& r) {
        double e = 0;
        for (size_t i = 0; i < r.samples.size(); ++i) {
          const double d = static_cast<double>(r.samples[i]) - y.samples[i];
          e += d * d;
        }
        return e;
      };
      // Fewer bits at no higher error (lossy: QP' 30, a fine step against the noise).
      EXPECT_LE(ssd(ey.reconstruction), ssd(plain.reconstruction));
      EXPECT_LT(ey.bytes.size(), 0.8 * plain.bytes.size());
      EXPECT_GT(scales_coded(ey.stats, true), 8);
      EXPECT_EQ(scales_coded(ey.stats, false), 16);  // every macroblock codes a scale
      // The decoder: X's residual as the encoder kept it, Y as the encoder reconstructed it.
      CrossPlaneLinks dx_links{nullptr, &decoded_x_residual};
      auto dx = decode_plane(ex.bytes, 64, 64, p, nullptr, nullptr, nullptr, nullptr, &dx_links);
      ASSERT_TRUE(dx.is_ok()) << dx.status().message();
      EXPECT_EQ(dx->samples, ex.reconstruction.samples);
      EXPECT_EQ(decoded_x_residual.samples, x_residual.samples);
      auto dy = decode_plane(ey.bytes, 64, 64, p, nullptr, nullptr, nullptr, nullptr, &y_links);
      ASSERT_TRUE(dy.is_ok()) << dy.status().message();
      EXPECT_EQ(dy->samples, ey.reconstruction.samples);
      if (lossless) {
        EXPECT_EQ(dy->samples, y.samples);
      }
    }
}

double max_error(const GeometryImage& a, const GeometryImage& b) {
  double worst = 0;
  for (int y = 0; y < a.xyz_mm.rows; ++y)
    for (int x = 0; x < a.xyz_mm.cols; ++x)
      if (a.domain_mask.at<uint8_t>(y, x))
        worst =
            std::max(worst, cv::norm(a.xyz_mm.at<cv::Vec3f>(y, x) - b.xyz_mm.at<cv::Vec3f>(y, x)));
  return worst;
}

TEST(CrossPlane, EncoderReconstructionEqualsDecoderOutputBitExactly) {
  const auto frames = testing::make_moving_analytic_video(48, 5);
  const SequenceInfo info = testing::info_for(frames);
  struct Case {
    const char* name;
    EncoderOptions o;
  };
  std::vector<Case> cases;
  for (const Preset preset : {Preset::kFast, Preset::kSlow})
    for (const int bframes : {0, 1}) {
      EncoderOptions o;
      o.qp = 0;
      o.preset = preset;
      o.bframes = bframes;
      o.intra_period = 4;
      o.cross_plane = true;
      cases.push_back({bframes ? "qp 0, B frames" : "qp 0, P frames", o});
    }
  EncoderOptions lossless;
  lossless.lossless = true;
  lossless.preset = Preset::kFast;
  lossless.cross_plane = true;
  cases.push_back({"lossless", lossless});
  EncoderOptions near = lossless;
  near.lossless = false;
  near.max_error_mm = 0.05;
  near.shared_motion = true;
  near.threads = 3;
  cases.push_back({"near-lossless, shared motion, 3 threads", near});
  EncoderOptions intra;
  intra.qp = -12;
  intra.intra_only = true;
  intra.preset = Preset::kSlow;
  intra.cross_plane = true;
  cases.push_back({"intra only, qp -12", intra});
  int64_t nonzero = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.name) + " " + preset_name(c.o.preset));
    std::vector<FrameCodingStats> stats;
    const std::string bytes = testing::writer_round_trip(frames, info, c.o, &stats);
    auto reader = GvidReader::open_memory(bytes, "x.gvid");
    ASSERT_TRUE(reader.is_ok());
    for (int64_t f = 0; f < (*reader)->frame_count(); ++f) {
      auto d = (*reader)->decode_frame(f);
      ASSERT_TRUE(d.is_ok());
      if (c.o.lossless) {
        EXPECT_TRUE(testing::same_samples(
            d->xyz_mm, dequantize_geometry(quantize_geometry(frames[f], info), info, f).xyz_mm));
      }
      if (c.o.max_error_mm > 0) {
        EXPECT_LE(max_error(frames[f], *d), c.o.max_error_mm);
      }
    }
    for (const auto& s : stats) {
      EXPECT_EQ(scales_coded(s.planes[0], false), 0);  // X codes no scale
      for (int p = 1; p < 3; ++p) nonzero += scales_coded(s.planes[p], true);
    }
  }
  EXPECT_GT(nonzero, 0);  // the tool was used
}

TEST(CrossPlane, OffAndOnSignalTheToolInEveryFrame) {
  const auto frames = testing::make_moving_analytic_video(48, 4);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.qp = 0;
  o.preset = Preset::kFast;
  o.intra_period = 3;
  for (const bool on : {false, true}) {
    o.cross_plane = on;
    auto stream = encode_gvid(frames, info, o);
    ASSERT_TRUE(stream.is_ok());
    auto reader = GvidReader::open_memory(*stream, "x.gvid").value();
    for (int64_t f = 0; f < reader->frame_count(); ++f)
      EXPECT_EQ((reader->packet_header(f).value().flags2 & format::kFrame2CrossPlane) != 0, on)
          << "frame " << f;
  }
}

TEST(CrossPlane, BadSyntaxIsRejectedWithAMessage) {
  const auto frames = testing::make_moving_analytic_video(32, 1);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.qp = 0;
  o.preset = Preset::kFast;
  o.intra_only = true;
  o.max_transform = 4;  // flags2 then holds the cross-plane bit alone
  o.deblocking = false;
  o.cross_plane_contexts = false;
  o.cross_plane = true;
  auto stream = encode_gvid(frames, info, o);
  ASSERT_TRUE(stream.is_ok());
  auto reader = GvidReader::open_memory(*stream, "x.gvid");
  ASSERT_TRUE(reader.is_ok());
  const std::string packet =
      testing::first_packet(*stream, static_cast<size_t>((*reader)->header_bytes()));
  ASSERT_TRUE(decode_frame_packet(packet, info, 0).is_ok());
  // Flags2 bit 7 (temporal contexts) in this intra frame is rejected (bits 4 and 5:
  // cross_plane_contexts_test and partition_test; bit 6: deblocking_test).
  for (const uint8_t bits : {128}) {
    auto d = decode_frame_packet(testing::with_flags2(packet, format::kFrame2CrossPlane | bits),
                                 info, 0);
    ASSERT_FALSE(d.is_ok());
    EXPECT_NE(d.status().message().find("temporal contexts in an intra frame"), std::string::npos)
        << d.status().message();
  }
  // Random damage in the payload (CRC fixed up, so that it reaches the macroblock layer): a
  // Status naming the plane or samples, never a crash (ASan runs this too).
  std::mt19937 rng(5);
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
  // Without the bit the Y and Z segments are read without the scales: they no longer parse, or
  // parse into other samples than the encoder's.
  auto cleared = decode_frame_packet(testing::with_flags2(packet, 0), info, 0);
  if (cleared.is_ok()) {
    const auto right = decode_frame_packet(packet, info, 0);
    ASSERT_TRUE(right.is_ok());
    EXPECT_FALSE(testing::same_samples(cleared->xyz_mm, right->xyz_mm));
  } else {
    EXPECT_NE(cleared.status().message().find("plane Y"), std::string::npos)
        << cleared.status().message();
  }
}

TEST(CrossPlane, OptionIsReportedInThePacketOfEveryFrameType) {
  // B frames carry the bit too (and nothing else of flags2).
  const auto frames = testing::make_moving_analytic_video(32, 3);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.qp = 0;
  o.preset = Preset::kFast;
  o.bframes = 1;
  o.cross_plane = true;
  std::vector<FrameCodingStats> stats;
  const std::string bytes = testing::writer_round_trip(frames, info, o, &stats);
  ASSERT_EQ(stats.size(), 3u);
  EXPECT_TRUE(stats[1].bidirectional);
}

// Cross-plane prediction with several reference frames and 8x8 / 16x16 transforms: the decoder
// reproduces the encoder's reconstruction bit for bit in lossy fast and slow coding with P and with
// B frames, and in lossless and near-lossless coding (where the larger transforms do not apply and
// refs is set explicitly); every tool is used.
TEST(CrossPlane, WithMultipleReferencesAndLargerTransformsDecodesBitExactly) {
  const auto frames = testing::make_moving_analytic_video(48, 7);
  const SequenceInfo info = testing::info_for(frames);
  struct Case {
    std::string name;
    EncoderOptions o;
  };
  std::vector<Case> cases;
  // QP 6 and 24 (at high QPs the encoder often tries a larger transform that quantizes to
  // nothing: X's residual must then be the one the decoder sees).
  for (const Preset preset : {Preset::kFast, Preset::kSlow})
    for (const int bframes : {0, 2})
      for (const int qp : {6, 24}) {
        EncoderOptions o;
        o.qp = qp;
        o.preset = preset;
        o.bframes = bframes;
        o.b_qp_offset = 4;
        o.refs = 3;
        o.max_transform = 16;
        o.cross_plane = true;
        cases.push_back({std::string(preset_name(preset)) +
                             (bframes ? ", B frames" : ", P frames") + ", qp " + std::to_string(qp),
                         o});
      }
  EncoderOptions lossless;
  lossless.lossless = true;
  lossless.preset = Preset::kFast;
  lossless.bframes = 0;
  lossless.refs = 3;
  lossless.cross_plane = true;
  cases.push_back({"lossless, P frames", lossless});
  EncoderOptions near = lossless;
  near.lossless = false;
  near.max_error_mm = 0.05;
  near.preset = Preset::kSlow;
  near.refs = 2;
  near.shared_motion = true;
  cases.push_back({"near-lossless, slow, shared motion", near});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    std::vector<FrameCodingStats> stats;
    const std::string bytes = testing::writer_round_trip(frames, info, c.o, &stats);
    // Which tools the packets announce, and what the Y and Z planes used.
    auto reader = GvidReader::open_memory(bytes, "x.gvid");
    ASSERT_TRUE(reader.is_ok());
    uint8_t flags2 = 0;
    for (int64_t f = 0; f < (*reader)->frame_count(); ++f) {
      auto h = (*reader)->packet_header(f);
      ASSERT_TRUE(h.is_ok());
      EXPECT_TRUE(h->flags2 & format::kFrame2CrossPlane) << "frame " << f;
      flags2 |= h->flags2;
      if (c.o.max_error_mm > 0) {
        auto d = (*reader)->decode_frame(f);
        ASSERT_TRUE(d.is_ok());
        EXPECT_LE(max_error(frames[f], *d), c.o.max_error_mm);
      }
    }
    EXPECT_TRUE(flags2 & format::kFrame2MultiRef);
    const bool bypass = c.o.lossless || c.o.max_error_mm > 0;
    EXPECT_EQ((flags2 & format::kFrame2LargeTransforms) != 0, !bypass);
    int64_t scales = 0, large = 0;
    for (const auto& s : stats)
      for (int p = 0; p < 3; ++p) {
        if (p > 0) scales += scales_coded(s.planes[p], true);
        large += s.planes[p].transform8_mbs + s.planes[p].transform16_mbs;
      }
    EXPECT_GT(scales, 0);
    if (!bypass) {
      EXPECT_GT(large, 0);
    }
  }
}

// Plane level: an I16x16 / inter macroblock with an 8x8 or 16x16 residual keeps X's residual
// for Y and Z as the decoder reconstructs it, and Y's scales apply on top of its larger
// transforms (P planes with two references).
TEST(CrossPlane, LargerTransformResidualsAreTheSourceAndTheTarget) {
  const SamplePlane x = noisy_plane(3), y = half_of(x);
  const SamplePlane x0 = noisy_plane(4), y0 = half_of(x0), x1 = noisy_plane(5), y1 = half_of(x1);
  int64_t large = 0;
  for (const bool rdo : {false, true})
    for (const bool inter : {false, true})
      for (const int max_transform : {8, 16}) {
        SCOPED_TRACE(std::string(rdo ? "slow" : "fast") + (inter ? " P" : " I") + " max " +
                     std::to_string(max_transform));
        PlaneCodingParams p;
        p.qp_prime = 24;
        p.rdo = rdo;
        p.max_transform = max_transform;
        p.ref_count = inter ? 2 : 1;
        const std::vector<const SamplePlane*> more_x = {&x1}, more_y = {&y1};
        const SamplePlane* ref_x = inter ? &x0 : nullptr;
        const SamplePlane* ref_y = inter ? &y0 : nullptr;
        CrossPlaneResidual x_residual, decoded_x_residual;
        CrossPlaneLinks x_links{nullptr, &x_residual};
        const PlaneEncodeResult ex =
            encode_plane(x, p, ref_x, nullptr, nullptr, inter ? &more_x : nullptr, &x_links);
        CrossPlaneLinks y_links{&x_residual, nullptr};
        const PlaneEncodeResult ey =
            encode_plane(y, p, ref_y, nullptr, nullptr, inter ? &more_y : nullptr, &y_links);
        // (The fast preset's intra decision rarely takes I16x16 on this noise: larger
        // transforms are counted over all cases below.)
        large += ex.stats.transform8_mbs + ex.stats.transform16_mbs + ey.stats.transform8_mbs +
                 ey.stats.transform16_mbs;
        EXPECT_GT(scales_coded(ey.stats, true), 0);
        CrossPlaneLinks dx_links{nullptr, &decoded_x_residual};
        auto dx = decode_plane(ex.bytes, 64, 64, p, ref_x, nullptr, nullptr,
                               inter ? &more_x : nullptr, &dx_links);
        ASSERT_TRUE(dx.is_ok()) << dx.status().message();
        EXPECT_EQ(dx->samples, ex.reconstruction.samples);
        EXPECT_EQ(decoded_x_residual.samples, x_residual.samples);
        // X's kept residual is what its reconstruction added to the prediction: where X is
        // intra-coded with a larger transform, source - recon is small against the residual.
        int64_t kept = 0;
        for (int32_t v : x_residual.samples) kept += v != 0;
        EXPECT_GT(kept, 64 * 64 / 2);
        auto dy = decode_plane(ey.bytes, 64, 64, p, ref_y, nullptr, nullptr,
                               inter ? &more_y : nullptr, &y_links);
        ASSERT_TRUE(dy.is_ok()) << dy.status().message();
        EXPECT_EQ(dy->samples, ey.reconstruction.samples);
      }
  EXPECT_GT(large, 0);
}

}  // namespace
}  // namespace gvkit::codec
