// Plane coding: the decoder reproduces the encoder's reconstruction bit for bit (every type of
// decision: RDO and fast, lossless and lossy, geometry modes on and off, 8..16 bits); lossless
// is exact; lossy error is bounded by the quantizer; garbage is rejected, never crashes.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "gvkit/codec/plane_coding.hpp"
#include "gvkit/codec/transform.hpp"

namespace gvkit::codec {
namespace {

// A smooth surface with a ridge and noise: exercises every macroblock type.
SamplePlane test_plane(int w, int h, int bit_depth, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, 1);
  SamplePlane p;
  p.width = w;
  p.height = h;
  p.samples.resize(static_cast<size_t>(w) * h);
  const double max_value = (1 << bit_depth) - 1;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double v = 0.5 + 0.3 * std::sin(x * 0.07 + y * 0.03) + 0.1 * (x > w / 2 ? 1 : 0) +
                 0.002 * noise(rng);
      v = std::clamp(v, 0.0, 1.0) * max_value;
      p.at(x, y) = static_cast<uint16_t>(std::lround(v));
    }
  return p;
}

void expect_round_trip(const SamplePlane& plane, const PlaneCodingParams& params) {
  const PlaneEncodeResult enc = encode_plane(plane, params);
  auto dec = decode_plane(enc.bytes, plane.width, plane.height, params);
  ASSERT_TRUE(dec.is_ok()) << dec.status().message();
  ASSERT_EQ(dec->samples, enc.reconstruction.samples);
}

TEST(PlaneCoding, LosslessIsExactInEveryConfiguration) {
  for (int bit_depth : {8, 12, 16})
    for (bool rdo : {true, false})
      for (bool gv : {true, false}) {
        const SamplePlane plane = test_plane(48, 32, bit_depth, 1);
        PlaneCodingParams params;
        params.bit_depth = bit_depth;
        params.lossless = true;
        params.rdo = rdo;
        params.geometry_modes = gv;
        params.adaptive_levels = gv == rdo;
        const PlaneEncodeResult enc = encode_plane(plane, params);
        EXPECT_EQ(enc.reconstruction.samples, plane.samples);
        auto dec = decode_plane(enc.bytes, plane.width, plane.height, params);
        ASSERT_TRUE(dec.is_ok()) << dec.status().message();
        EXPECT_EQ(dec->samples, plane.samples) << "bits " << bit_depth << " rdo " << rdo;
      }
}

TEST(PlaneCoding, LossyDecoderMatchesEncoderAndErrorIsBounded) {
  for (int qp : {0, 20, 40, 51})
    for (bool rdo : {true, false}) {
      const int bit_depth = 16;
      const SamplePlane plane = test_plane(64, 48, bit_depth, 2);
      PlaneCodingParams params;
      params.bit_depth = bit_depth;
      params.qp_prime = qp + 6 * (bit_depth - 8);
      params.rdo = rdo;
      const PlaneEncodeResult enc = encode_plane(plane, params);
      auto dec = decode_plane(enc.bytes, plane.width, plane.height, params);
      ASSERT_TRUE(dec.is_ok()) << dec.status().message();
      ASSERT_EQ(dec->samples, enc.reconstruction.samples) << "qp " << qp;
      int64_t worst = 0;
      for (size_t i = 0; i < plane.samples.size(); ++i)
        worst = std::max<int64_t>(worst, std::abs(int(plane.samples[i]) - int(dec->samples[i])));
      EXPECT_LE(worst, 8 * quantizer_step(params.qp_prime) * (2.0 / 3.0) + 6) << "qp " << qp;
    }
}

TEST(PlaneCoding, PredictedPlanesRoundTrip) {
  for (bool lossless : {true, false})
    for (bool rdo : {false, true}) {
      const SamplePlane previous = test_plane(48, 32, 16, 5);
      SamplePlane current = previous;
      // Shift by 2 samples and add a value offset: motion plus value change.
      for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 48; ++x)
          current.at(x, y) = static_cast<uint16_t>(previous.at(std::max(0, x - 2), y) + 40);
      PlaneCodingParams params;
      params.lossless = lossless;
      params.qp_prime = 60;
      params.rdo = rdo;
      const PlaneEncodeResult ref = encode_plane(previous, params);
      const PlaneEncodeResult enc = encode_plane(current, params, &ref.reconstruction);
      auto dec = decode_plane(enc.bytes, 48, 32, params, &ref.reconstruction);
      ASSERT_TRUE(dec.is_ok()) << dec.status().message() << " lossless " << lossless;
      ASSERT_EQ(dec->samples, enc.reconstruction.samples);
      if (lossless) {
        EXPECT_EQ(dec->samples, current.samples);
      }
      EXPECT_LT(enc.bytes.size(), ref.bytes.size());
    }
}

TEST(PlaneCoding, BitAccountingAddsUpToTheSegment) {
  const SamplePlane previous = test_plane(64, 48, 16, 7);
  SamplePlane current = previous;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x)
      current.at(x, y) = static_cast<uint16_t>(previous.at(std::max(0, x - 1), y) + 25);
  for (bool rdo : {false, true}) {
    PlaneCodingParams params;
    params.qp_prime = 50;
    params.rdo = rdo;
    params.td_prediction = true;
    params.subpel = 4;
    const PlaneEncodeResult intra = encode_plane(previous, params);
    const PlaneEncodeResult inter = encode_plane(current, params, &intra.reconstruction);
    for (const PlaneEncodeResult* r : {&intra, &inter}) {
      const double segment_bits = 8.0 * static_cast<double>(r->bytes.size());
      // Ideal code lengths: within the coder's flush and a fraction of a percent.
      EXPECT_NEAR(r->stats.total_bits(), segment_bits, 0.01 * segment_bits + 24) << rdo;
      EXPECT_EQ(r->stats.intra_mbs + r->stats.inter_mbs + r->stats.td_mbs + r->stats.skip_mbs,
                4 * 3);
      EXPECT_GT(r->stats.bits[kSyntaxLevels], 0.0);
    }
    EXPECT_EQ(intra.stats.intra_mbs, 12);
    EXPECT_EQ(intra.stats.bits[kSyntaxMotion], 0.0);
    EXPECT_GT(inter.stats.bits[kSyntaxMotion], 0.0);
    EXPECT_LT(inter.stats.intra_mbs, 12);
  }
}

TEST(PlaneCoding, EightBitLossyRoundTrip) {
  PlaneCodingParams params;
  params.bit_depth = 8;
  params.qp_prime = 30;
  expect_round_trip(test_plane(32, 32, 8, 3), params);
  params.geometry_modes = false;
  params.allow_8x8 = false;
  expect_round_trip(test_plane(32, 32, 8, 4), params);
}

TEST(PlaneCoding, GarbageIsRejectedOrDecodedNeverCrashes) {
  std::mt19937 rng(9);
  PlaneCodingParams params;
  params.qp_prime = 60;
  int failures = 0;
  for (int t = 0; t < 200; ++t) {
    std::string bytes(static_cast<size_t>(rng() % 64), '\0');
    for (char& c : bytes) c = static_cast<char>(rng());
    auto dec = decode_plane(bytes, 32, 32, params);
    if (!dec.is_ok()) {
      ++failures;
      const std::string& m = dec.status().message();
      EXPECT_TRUE(m.find("macroblock") != std::string::npos ||
                  m.find("end of plane") != std::string::npos)
          << m;
    }
  }
  EXPECT_GT(failures, 150);
}

}  // namespace
}  // namespace gvkit::codec
