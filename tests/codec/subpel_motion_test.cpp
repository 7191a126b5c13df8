// Quarter-sample motion compensation of P planes (frame flag bit 7): H.264 interpolation on 16-bit
// samples (exact on planes, in range at steps), encoder and decoder reconstructing the same
// samples, lossless round trips, and a surface shifted by a fraction of a sample predicted better
// with sub-sample motion than with whole samples.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/crc32.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/motion_compensation.hpp"
#include "gvkit/codec/plane_coding.hpp"

namespace gvkit::codec {
namespace {

// A smooth 16-bit surface sampled at (x + dx, y + dy).
SamplePlane smooth_plane(int size, double dx, double dy) {
  SamplePlane p;
  p.width = p.height = size;
  p.samples.resize(static_cast<size_t>(size) * size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double u = x + dx, v = y + dy;
      p.at(x, y) = static_cast<uint16_t>(
          std::lround(30000 + 9000 * std::sin(u * 0.21) * std::cos(v * 0.17) + 40 * u - 25 * v));
    }
  return p;
}

TEST(SubpelMotion, InterpolationIsExactOnAPlaneAndAtWholeSamples) {
  SamplePlane ramp;
  ramp.width = ramp.height = 24;
  ramp.samples.resize(24 * 24);
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) ramp.at(x, y) = static_cast<uint16_t>(1000 + 4 * x + 8 * y);
  // Away from the edges (the 6-tap filter reaches 2 samples left / 3 right), every quarter
  // position of f = 1000 + 4 x + 8 y is 1000 + xq + 2 yq.
  for (int yq = 4 * 3; yq < 4 * 20; ++yq)
    for (int xq = 4 * 3; xq < 4 * 20; ++xq)
      ASSERT_EQ(interpolate_quarter_sample(ramp, xq, yq, 16), 1000 + xq + 2 * yq)
          << "at (" << xq << ", " << yq << ") / 4";
  const SamplePlane wavy = smooth_plane(32, 0, 0);
  for (int y = -3; y < 35; ++y)
    for (int x = -3; x < 35; ++x)
      ASSERT_EQ(interpolate_quarter_sample(wavy, 4 * x, 4 * y, 16),
                wavy.at(std::clamp(x, 0, 31), std::clamp(y, 0, 31)));
  // motion_sample: whole-sample vectors in either unit give the same sample.
  EXPECT_EQ(motion_sample(wavy, 5, 7, 3, -2, false, 16),
            motion_sample(wavy, 5, 7, 12, -8, true, 16));
}

TEST(SubpelMotion, InterpolationStaysInRangeAtSteps) {
  for (int bit_depth : {8, 16}) {
    const int max_value = (1 << bit_depth) - 1;
    SamplePlane step;
    step.width = step.height = 16;
    step.samples.resize(256);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x)
        step.at(x, y) = static_cast<uint16_t>(((x / 3 + y / 5) & 1) ? max_value : 0);
    int32_t lo = max_value, hi = 0;
    for (int yq = -8; yq < 72; ++yq)
      for (int xq = -8; xq < 72; ++xq) {
        const int32_t v = interpolate_quarter_sample(step, xq, yq, bit_depth);
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    EXPECT_EQ(lo, 0) << bit_depth;  // the filter overshoots there and is clipped
    EXPECT_EQ(hi, max_value) << bit_depth;
  }
}

TEST(SubpelMotion, BlockPredictionEqualsTheSampleBySampleReference) {
  for (int bit_depth : {8, 16}) {
    SamplePlane noise;
    noise.width = 48;
    noise.height = 32;
    noise.samples.resize(48 * 32);
    uint32_t state = 12345;
    for (uint16_t& v : noise.samples) {
      state = state * 1664525u + 1013904223u;
      v = static_cast<uint16_t>((state >> 8) & ((1u << bit_depth) - 1));
    }
    int32_t fast[256], plain[256];
    // Every phase, inside and across every edge, 16x16 and 4x4 blocks.
    for (int size : {16, 4})
      for (int y0 : {0, 16})
        for (int x0 : {0, 16, 32})
          for (int mv_y = -23; mv_y <= 23; mv_y += 5)
            for (int mv_x = -21; mv_x <= 21; mv_x += 3) {
              predict_motion_block(noise, x0, y0, size, size, mv_x, mv_y, true, bit_depth, fast);
              predict_motion_block_reference(noise, x0, y0, size, size, mv_x, mv_y, true, bit_depth,
                                             plain);
              for (int i = 0; i < size * size; ++i)
                ASSERT_EQ(fast[i], plain[i]) << "B " << bit_depth << " block (" << x0 << ", " << y0
                                             << ") mv (" << mv_x << ", " << mv_y << ")";
            }
  }
}

struct Coded {
  size_t bytes = 0;
  SamplePlane decoded;
};

Coded code_p_plane(const SamplePlane& source, const SamplePlane& reference, PlaneCodingParams p) {
  const PlaneEncodeResult enc = encode_plane(source, p, &reference);
  auto dec = decode_plane(enc.bytes, source.width, source.height, p, &reference);
  EXPECT_TRUE(dec.is_ok()) << dec.status().message();
  if (!dec.is_ok()) return {};
  EXPECT_EQ(dec->samples, enc.reconstruction.samples) << "decoder differs from the encoder";
  return {enc.bytes.size(), std::move(dec).value()};
}

TEST(SubpelMotion, DecoderReconstructsWhatTheEncoderReconstructs) {
  const SamplePlane reference = smooth_plane(64, 0, 0);
  const SamplePlane source = smooth_plane(64, 1.25, -0.75);
  for (int subpel : {2, 4})
    for (bool td : {false, true})
      for (bool rdo : {false, true})
        for (int qp_prime : {30, 60}) {
          PlaneCodingParams p;
          p.subpel = subpel;
          p.td_prediction = td;
          p.rdo = rdo;
          p.qp_prime = qp_prime;
          SCOPED_TRACE("subpel " + std::to_string(subpel) + " td " + std::to_string(td) + " rdo " +
                       std::to_string(rdo) + " qp' " + std::to_string(qp_prime));
          code_p_plane(source, reference, p);
        }
}

TEST(SubpelMotion, LosslessAndNearLosslessPlanesRoundTrip) {
  const SamplePlane reference = smooth_plane(48, 0, 0);
  const SamplePlane source = smooth_plane(48, 0.5, 0.25);
  for (int near : {0, 3}) {
    PlaneCodingParams p;
    p.lossless = true;
    p.adaptive_levels = true;
    p.near_lossless = near;
    p.subpel = 4;
    const Coded c = code_p_plane(source, reference, p);
    ASSERT_EQ(c.decoded.samples.size(), source.samples.size());
    for (size_t i = 0; i < source.samples.size(); ++i)
      ASSERT_LE(std::abs(c.decoded.samples[i] - source.samples[i]), near) << i;
  }
}

TEST(SubpelMotion, FractionalShiftIsPredictedBetterThanWithWholeSamples) {
  const SamplePlane reference = smooth_plane(64, 0, 0);
  const SamplePlane source = smooth_plane(64, 0.5, 0.25);
  PlaneCodingParams p;
  p.lossless = true;
  p.adaptive_levels = true;
  p.td_prediction = false;  // motion compensation alone
  size_t bytes[3];
  for (int i = 0; i < 3; ++i) {
    p.subpel = i * 2;
    bytes[i] = code_p_plane(source, reference, p).bytes;
  }
  // Lossless: the residual is what the prediction missed.
  EXPECT_LT(bytes[1], bytes[0] * 0.9) << "half-sample " << bytes[1] << " vs whole " << bytes[0];
  EXPECT_LT(bytes[2], bytes[1]) << "quarter-sample " << bytes[2] << " vs half " << bytes[1];
}

TEST(SubpelMotion, LosslessStreamsWithSubpelAreExact) {
  testing::GeometryVideoOptions vo;
  vo.size = 48;
  vo.frames = 3;
  const auto frames = testing::make_analytic_video(vo);
  auto info = make_sequence_info(frames, 16, 30.0);
  ASSERT_TRUE(info.is_ok());
  EncoderOptions o;
  o.lossless = true;
  o.preset = Preset::kFast;
  ASSERT_EQ(o.subpel, 4);  // the default
  auto bytes = encode_gvid(frames, *info, o);
  ASSERT_TRUE(bytes.is_ok()) << bytes.status().message();
  auto reader = GvidReader::open_memory(*bytes, "subpel.gvid");
  ASSERT_TRUE(reader.is_ok()) << reader.status().message();
  // Decoded = the input quantized: within half a quantization step per axis.
  const double bound = std::sqrt(3.0) * 0.5 * info->step_mm() + 1e-6;
  for (int64_t f = 0; f < 3; ++f) {
    auto decoded = (*reader)->decode_frame(f);
    ASSERT_TRUE(decoded.is_ok()) << decoded.status().message();
    EXPECT_LE(geometry_error(frames[f], *decoded).max_mm, bound) << f;
  }
  o.subpel = 3;
  const Status bad = o.check();
  ASSERT_FALSE(bad.is_ok());
  EXPECT_NE(bad.message().find("subpel 3"), std::string::npos) << bad.message();
}

TEST(SubpelMotion, QuarterSampleFlagInAnIntraFrameIsCorrupt) {
  testing::GeometryVideoOptions vo;
  vo.size = 32;
  vo.frames = 1;
  const auto frames = testing::make_analytic_video(vo);
  auto info = make_sequence_info(frames, 16, 30.0);
  ASSERT_TRUE(info.is_ok());
  EncoderOptions o;
  o.qp = 6;
  o.preset = Preset::kFast;
  auto bytes = encode_gvid(frames, *info, o);
  ASSERT_TRUE(bytes.is_ok());
  size_t header_size = 0;
  ASSERT_TRUE(format::read_file_header(*bytes, &header_size).is_ok());
  std::string damaged = *bytes;
  // Set flag bit 7 in the I frame's packet header and make its header CRC right again.
  auto packet = format::read_packet_header(std::string_view(damaged).substr(header_size));
  ASSERT_TRUE(packet.is_ok());
  packet->flags |= format::kFrameQuarterPel;
  damaged.replace(header_size, packet->header_size, format::write_packet_header(*packet));
  auto reader = GvidReader::open_memory(damaged, "flag.gvid");
  ASSERT_TRUE(reader.is_ok()) << reader.status().message();
  auto frame = (*reader)->decode_frame(0);
  ASSERT_FALSE(frame.is_ok());
  EXPECT_NE(frame.status().message().find("inter tools in an intra frame"), std::string::npos)
      << frame.status().message();
}

}  // namespace
}  // namespace gvkit::codec
