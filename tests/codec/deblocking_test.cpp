// The deblocking filter (flags2 bit 6, docs/bitstream.md 4.12): the kernel leaves
// linear surfaces, real edges and strength-0 edges alone and shrinks blocking steps, within the
// sample range; in streams the decoder reproduces the encoder's (filtered) reconstruction bit
// for bit in I, P and B frames of both presets, the filter lowers the error of a coarse encode,
// lossless and near-lossless streams never use it, off no packet has the bit, and a
// packet that asks for it in a lossless frame or lacks its parameters is rejected.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "deblocking_strengths.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/deblocking.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "packet_surgery.hpp"

namespace gvkit::codec {
namespace {

SamplePlane make_plane(int size, const auto& value) {
  SamplePlane p;
  p.width = p.height = size;
  p.samples.resize(static_cast<size_t>(size) * size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) p.at(x, y) = static_cast<uint16_t>(value(x, y));
  return p;
}

DeblockingStrengths all_edges(int size, uint8_t strength) {
  DeblockingStrengths s;
  s.reset(size / 4, size / 4);
  std::fill(s.vertical.begin(), s.vertical.end(), strength);
  std::fill(s.horizontal.begin(), s.horizontal.end(), strength);
  return s;
}

constexpr int kQpPrime = 60;  // step 640 samples: beta 960, tc 160 (x 2 at strength 2)

TEST(Deblocking, StepIsAnExactIntegerTable) {
  EXPECT_EQ(deblocking_step16(0), 10);
  EXPECT_EQ(deblocking_step16(5), 18);
  EXPECT_EQ(deblocking_step16(6), 20);
  EXPECT_EQ(deblocking_step16(60), 10 << 10);
  EXPECT_EQ(deblocking_step16(99), int64_t{14} << 16);
  for (int qp = 0; qp <= 99; ++qp)
    EXPECT_NEAR(deblocking_step16(qp) / 16.0, 0.625 * std::pow(2.0, qp / 6.0),
                0.04 * 0.625 * std::pow(2.0, qp / 6.0));
}

TEST(Deblocking, LinearSurfacesAreLeftAlone) {
  // Steep ramps in both directions (a geometry image's x and y planes) pass unchanged.
  const SamplePlane ramp = make_plane(32, [](int x, int y) { return 1000 + 230 * x + 170 * y; });
  SamplePlane filtered = ramp;
  deblock_plane(filtered, all_edges(32, 2), kQpPrime, 16, {});
  EXPECT_EQ(filtered.samples, ramp.samples);
}

TEST(Deblocking, ShrinksABlockingStepAndKeepsRealEdgesAndStrengthZero) {
  // A smooth ramp whose right half (from the block edge at x = 16) is offset by `step`.
  const auto stepped = [](int step) {
    return make_plane(
        32, [step](int x, int y) { return 20000 + 100 * x + 10 * y + (x >= 16 ? step : 0); });
  };
  const DeblockingParams params;  // tc = 4 / 16 of 640 = 160 at strength 1
  {
    SamplePlane p = stepped(200);
    deblock_plane(p, all_edges(32, 1), kQpPrime, 16, params);
    for (int y = 0; y < 32; ++y) {
      const int before = 200 + 100, after = p.at(16, y) - p.at(15, y);
      EXPECT_LT(std::abs(after - 100), std::abs(before - 100)) << "row " << y;
    }
  }
  {
    // 50 times tc: a real edge of the surface, not blocking.
    const SamplePlane edge = stepped(12000);
    SamplePlane p = edge;
    deblock_plane(p, all_edges(32, 1), kQpPrime, 16, params);
    EXPECT_EQ(p.samples, edge.samples);
  }
  {
    const SamplePlane blocky = stepped(200);
    SamplePlane p = blocky;
    deblock_plane(p, all_edges(32, 0), kQpPrime, 16, params);
    EXPECT_EQ(p.samples, blocky.samples);
  }
}

TEST(Deblocking, KeepsSamplesBetweenTheBlocksValues) {
  // Flat blocks at the top of the range alternating by a step the filter acts on: filtered
  // samples move toward the other side, never past it or out of the range (a wrong sign or a
  // 16-bit wrap-around would).
  for (const int bit_depth : {8, 16}) {
    const int max_value = (1 << bit_depth) - 1;
    const SamplePlane p0 = make_plane(32, [&](int x, int y) {
      return ((x / 8 + y / 8) % 2) ? max_value : max_value - (bit_depth == 8 ? 3 : 200);
    });
    SamplePlane p = p0;
    deblock_plane(p, all_edges(32, 2), bit_depth == 8 ? 40 : kQpPrime, bit_depth, {});
    EXPECT_NE(p.samples, p0.samples);
    const auto [lo, hi] = std::minmax_element(p0.samples.begin(), p0.samples.end());
    for (const uint16_t v : p.samples) {
      EXPECT_GE(v, *lo);
      EXPECT_LE(v, *hi);
    }
  }
}

// Every lossy packet carries flags2 bit 6 when on, none when off.
void expect_deblocked(const std::string& stream, bool on) {
  auto reader = GvidReader::open_memory(stream, "x.gvid");
  ASSERT_TRUE(reader.is_ok());
  for (int64_t f = 0; f < (*reader)->frame_count(); ++f)
    EXPECT_EQ(((*reader)->packet_header(f)->flags2 & format::kFrame2Deblocking) != 0, on);
}

TEST(Deblocking, DecoderReproducesTheFilteredReconstructionBitExactly) {
  const auto frames = testing::make_moving_analytic_video(48, 6);
  const SequenceInfo info = testing::info_for(frames);
  for (const Preset preset : {Preset::kFast, Preset::kSlow})
    for (const int qp : {0, 18}) {
      SCOPED_TRACE(std::string(preset_name(preset)) + " qp " + std::to_string(qp));
      EncoderOptions o;
      o.qp = qp;
      o.preset = preset;
      o.intra_period = 4;  // I P B P, I P
      o.threads = 2;
      expect_deblocked(testing::writer_round_trip(frames, info, o), true);
    }
  const auto frames8 = testing::make_moving_analytic_video(32, 3);
  EncoderOptions eight;
  eight.bit_depth = 8;
  eight.qp = 24;
  expect_deblocked(testing::writer_round_trip(frames8, testing::info_for(frames8, 8), eight), true);
}

// Mean squared error (mm^2) of a decoded stream against its source over the domain.
double stream_mse(const std::string& stream, const std::vector<GeometryImage>& frames) {
  auto reader = GvidReader::open_memory(stream, "x.gvid").value();
  GeometryError total;
  for (int64_t f = 0; f < reader->frame_count(); ++f)
    accumulate(total, geometry_error(frames[f], reader->decode_frame(f).value()));
  return total.rms_mm * total.rms_mm;
}

TEST(Deblocking, LowersTheErrorOfACoarseEncodeAtAboutTheSameRate) {
  const auto frames = testing::make_moving_analytic_video(64, 4);
  const SequenceInfo info = testing::info_for(frames);
  for (const Preset preset : {Preset::kFast, Preset::kSlow}) {
    SCOPED_TRACE(preset_name(preset));
    EncoderOptions on;
    on.qp = 18;
    on.preset = preset;
    on.resolution = Resolution::kFull;  // (at half resolution the upsampling smooths the edges)
    EncoderOptions off = on;
    off.deblocking = false;
    const std::string a = encode_gvid(frames, info, on).value();
    const std::string b = encode_gvid(frames, info, off).value();
    expect_deblocked(b, false);
    EXPECT_LT(stream_mse(a, frames), 0.95 * stream_mse(b, frames));
    EXPECT_LT(a.size(), 1.05 * b.size());
  }
}

TEST(Deblocking, LosslessAndNearLosslessStreamsDoNotUseIt) {
  const auto frames = testing::make_moving_analytic_video(32, 3);
  const SequenceInfo info = testing::info_for(frames);
  for (const bool lossless : {true, false}) {
    SCOPED_TRACE(lossless ? "lossless" : "near-lossless");
    EncoderOptions o;
    o.lossless = lossless;
    o.max_error_mm = lossless ? 0 : 0.05;
    EncoderOptions off = o;
    off.deblocking = false;
    const std::string a = encode_gvid(frames, info, o).value();
    EXPECT_EQ(a, encode_gvid(frames, info, off).value());
    auto reader = GvidReader::open_memory(a, "x.gvid").value();
    for (int64_t f = 0; f < reader->frame_count(); ++f)
      EXPECT_EQ(reader->packet_header(f)->flags2 & format::kFrame2Deblocking, 0);
  }
}

TEST(Deblocking, RejectsTheFlagInALosslessFrameAndMissingParameters) {
  const auto frames = testing::make_moving_analytic_video(32, 1);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions lossless;
  lossless.lossless = true;
  lossless.intra_only = true;
  const std::string stream = encode_gvid(frames, info, lossless).value();
  const size_t header = GvidReader::open_memory(stream, "x.gvid").value()->header_bytes();
  const std::string packet = testing::first_packet(stream, header);
  const auto flags2 =
      static_cast<uint8_t>(format::read_packet_header(packet)->flags2 | format::kFrame2Deblocking);
  auto bad = decode_frame_packet(testing::with_flags2(packet, flags2), info, 0);
  ASSERT_FALSE(bad.is_ok());
  EXPECT_NE(bad.status().message().find("deblocking in a lossless frame"), std::string::npos)
      << bad.status().message();

  // A lossy intra packet whose payload ends before the two parameter bytes.
  EncoderOptions lossy;
  lossy.intra_only = true;
  const std::string lossy_stream = encode_gvid(frames, info, lossy).value();
  const std::string lossy_packet = testing::first_packet(
      lossy_stream, GvidReader::open_memory(lossy_stream, "x.gvid").value()->header_bytes());
  // Payload: plane count, max transform, then the deblocking bytes; keep the first two only.
  const std::string payload = testing::packet_payload(lossy_packet).substr(0, 2);
  auto truncated = decode_frame_packet(testing::with_payload(lossy_packet, payload), info, 0);
  ASSERT_FALSE(truncated.is_ok());
  EXPECT_NE(truncated.status().message().find("deblocking parameters missing"), std::string::npos)
      << truncated.status().message();
}

// deblocking_strengths (macroblock by macroblock, with its intra-like and inter-pair shortcuts)
// against the edge-by-edge reference on random plane states of every kind: P planes with and
// without partitions, B planes, whole-sample and quarter-sample vectors; intra, TD and inter
// macroblocks with every transform, coded-block flags and vectors that differ by less and more
// than a sample.
TEST(DeblockingStrengths, MacroblockWiseEqualsEdgeWise) {
  std::mt19937 rng(7);
  const auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  int differing = 0, intra_edges = 0, other_edges = 0, zero_edges = 0;
  for (int round = 0; round < 240; ++round) {
    detail::PlaneState st(16 * (1 + pick(6)), 16 * (1 + pick(5)));
    st.bidirectional = round % 3 == 1;
    if (round % 3 == 2) st.enable_partitions();
    // Every other round mostly skips with nearly equal vectors (edges of strength 0 between
    // inter macroblocks), else vectors that often differ.
    const bool calm = round % 2 == 0;
    const int spread = calm ? 3 : 9;
    const auto vector = [&] { return static_cast<int16_t>(pick(spread) - spread / 2); };
    for (size_t m = 0; m < st.mb_type.size(); ++m) {
      st.mb_type[m] = static_cast<uint8_t>(pick(calm ? 6 : 3) ? detail::kMbInter : pick(3));
      st.td[m] = st.mb_type[m] == detail::kMbInter && pick(calm ? 6 : 2) == 0;
      st.transform[m] = static_cast<uint8_t>(pick(3));
      st.skip[m] = st.mb_type[m] == detail::kMbInter && !st.td[m] && pick(calm ? 4 : 3) != 0;
      st.mv_x[m] = vector();
      st.mv_y[m] = vector();
      st.mv_x1[m] = vector();
      st.mv_y1[m] = vector();
      st.ref_idx[m] = static_cast<uint8_t>(pick(calm ? 8 : 4) == 0);
      st.lists[m] = static_cast<uint8_t>(calm ? 3 : 1 + pick(3));
    }
    for (auto& f : st.cbf4) f = static_cast<uint8_t>(pick(3) == 0);
    if (st.partitions)
      for (size_t i = 0; i < st.grid.ref.size(); ++i) {
        st.grid.ref[i] = static_cast<int8_t>(pick(3) == 0);
        st.grid.mv_x[i] = static_cast<int16_t>(pick(9) - 4);
        st.grid.mv_y[i] = static_cast<int16_t>(pick(9) - 4);
      }
    for (const bool quarter_pel : {false, true}) {
      DeblockingStrengths fast, plain;
      detail::deblocking_strengths(st, quarter_pel, fast);
      detail::deblocking_strengths_reference(st, quarter_pel, plain);
      ASSERT_EQ(fast.blocks_x, plain.blocks_x);
      ASSERT_EQ(fast.blocks_y, plain.blocks_y);
      for (size_t i = 0; i < plain.vertical.size(); ++i) {
        differing += fast.vertical[i] != plain.vertical[i];
        differing += fast.horizontal[i] != plain.horizontal[i];
        (plain.vertical[i] == 2 ? intra_edges : other_edges) += 1;
        zero_edges += plain.vertical[i] == 0;
      }
    }
  }
  EXPECT_EQ(differing, 0);
  // Both kinds of edges were checked many times.
  EXPECT_GT(intra_edges, 1000);
  EXPECT_GT(other_edges, 1000);
  EXPECT_GT(zero_edges, 1000);
}

}  // namespace
}  // namespace gvkit::codec
