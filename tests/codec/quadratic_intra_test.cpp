// Quadratic intra (the payload's first byte bit 7, docs/bitstream.md 6.1): the mode predicts a
// quadratic surface exactly and a plane like H.264's plane mode, the decoder reproduces the
// encoder in every configuration (presets, I / P / B frames, lossless, near-lossless), the mode
// is coded and makes the ICT face's stream cheaper, and off no packet has the flag.
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/intra_prediction.hpp"
#include "gvkit/codec/quadratic_intra.hpp"
#include "packet_surgery.hpp"
#include "support/test_support.hpp"

namespace gvkit::codec {
namespace {

// A 48x48 plane of f(x, y) rounded, and the quadratic mode's prediction of its block (16, 16).
std::vector<int32_t> predict_centre(double (*f)(double, double), std::vector<uint16_t>* plane) {
  plane->resize(48 * 48);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) (*plane)[y * 48 + x] = static_cast<uint16_t>(std::lround(f(x, y)));
  std::vector<int32_t> out(256);
  predict_quadratic16(plane->data(), 48, 16, 16, 65535, out.data());
  return out;
}

// The forward-difference evaluation equals the per-sample definition bit for bit: random planes
// at 8, 12 and 16 bits (noise, so the fitted surfaces are steep and clip), saturated and
// alternating extremes, and smooth ramps, at every block offset of a 40x40 plane.
TEST(QuadraticIntra, ForwardDifferencesEqualTheDefinition) {
  std::mt19937 rng(7);
  std::vector<uint16_t> plane(40 * 40);
  int blocks = 0;
  for (int round = 0; round < 300; ++round) {
    const int bits = round % 3 == 0 ? 8 : (round % 3 == 1 ? 12 : 16);
    const int max_value = (1 << bits) - 1;
    std::uniform_int_distribution<int> sample(0, max_value);
    const int kind = round % 5;
    for (int y = 0; y < 40; ++y)
      for (int x = 0; x < 40; ++x) {
        int v = sample(rng);
        if (kind == 1) v = (x + y) % 2 ? max_value : 0;
        if (kind == 2) v = std::min(max_value, x * y * 40 + (v & 7));
        if (kind == 3) v = max_value - (v & 3);
        plane[static_cast<size_t>(y) * 40 + x] = static_cast<uint16_t>(v);
      }
    for (int y0 = 2; y0 + 16 <= 40; y0 += 11)
      for (int x0 = 2; x0 + 16 <= 40; x0 += 7) {
        std::vector<int32_t> fast(256), reference(256);
        predict_quadratic16(plane.data(), 40, x0, y0, max_value, fast.data());
        predict_quadratic16_reference(plane.data(), 40, x0, y0, max_value, reference.data());
        ASSERT_EQ(fast, reference) << "round " << round << " block " << x0 << "," << y0;
        ++blocks;
      }
  }
  EXPECT_EQ(blocks, 300 * 12);
}

TEST(QuadraticIntra, PredictsAQuadraticSurface) {
  std::vector<uint16_t> plane;
  const auto quadratic = [](double x, double y) {
    return 30000 + 40 * x - 25 * y + 3 * x * x - 2 * y * y + x * y;  // integer-valued
  };
  const std::vector<int32_t> out = predict_centre(quadratic, &plane);
  int worst = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      worst = std::max(worst, std::abs(out[y * 16 + x] - plane[(16 + y) * 48 + 16 + x]));
  EXPECT_EQ(worst, 0);
}

TEST(QuadraticIntra, MatchesThePlaneModeOnAPlaneAndBeatsItOnACurvedSurface) {
  std::vector<uint16_t> plane;
  const std::vector<int32_t> flat =
      predict_centre([](double x, double y) { return 1000 + 37 * x + 12 * y; }, &plane);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      EXPECT_EQ(flat[y * 16 + x], plane[(16 + y) * 48 + 16 + x]) << x << ", " << y;
  // A smooth curved surface (a face's cheek in geometry-image units): the H.264 plane mode
  // misses the curvature, the quadratic mode follows it.
  const std::vector<int32_t> curved = predict_centre(
      [](double x, double y) { return 30000 + 8000 * std::cos(x / 14) * std::cos(y / 18); },
      &plane);
  const IntraNeighbors nb = make_neighbors(plane.data(), 48, 16, 16, 16, true, true, false, 16);
  int32_t h264[256];
  predict_intra(16, 3, nb, 65535, h264);
  double quadratic_sse = 0, plane_sse = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const double truth = plane[(16 + y) * 48 + 16 + x];
      quadratic_sse += std::pow(curved[y * 16 + x] - truth, 2);
      plane_sse += std::pow(h264[y * 16 + x] - truth, 2);
    }
  EXPECT_LT(quadratic_sse * 4, plane_sse);
}

TEST(QuadraticIntra, DecoderReproducesTheEncoderInEveryConfiguration) {
  const auto frames = testing::make_moving_analytic_video(64, 5);
  const SequenceInfo info = testing::info_for(frames);
  std::vector<std::pair<std::string, EncoderOptions>> cases;
  for (const Preset preset : {Preset::kFast, Preset::kSlow})
    for (const bool intra_only : {false, true})
      for (const int qp : {0, 18}) {
        EncoderOptions o;
        o.preset = preset;
        o.intra_only = intra_only;
        o.qp = qp;
        o.intra_period = 4;
        cases.push_back({std::string(preset_name(preset)) + (intra_only ? " intra" : " IPB") +
                             " qp " + std::to_string(qp),
                         o});
      }
  EncoderOptions lossless;
  lossless.lossless = true;
  lossless.intra_only = true;
  cases.push_back({"lossless", lossless});
  EncoderOptions bounded;
  bounded.max_error_mm = 0.05;
  bounded.intra_only = true;
  cases.push_back({"near-lossless", bounded});
  int64_t total = 0;
  for (const auto& [what, o] : cases) {
    SCOPED_TRACE(what);
    ASSERT_TRUE(o.quadratic_intra);  // on by default
    std::vector<FrameCodingStats> stats;
    const std::string stream = testing::writer_round_trip(frames, info, o, &stats);
    for (const auto& [type, flags] : testing::payload_flags(stream))
      EXPECT_TRUE(flags & format::kPayloadQuadraticIntra);
    for (const FrameCodingStats& f : stats)
      for (const PlaneCodingStats& p : f.planes) total += p.quadratic_mbs;
  }
  EXPECT_GT(total, 0);  // the mode is taken
}

// The ICT face (when the shared data is present), intra only at a low rate: the stream with the
// mode is smaller and its geometry PSNR no more than 0.05 dB lower; off, no packet has the flag.
TEST(QuadraticIntra, MakesTheIctFaceCheaper) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  testing::GeometryVideoOptions vo;
  vo.size = 128;
  vo.frames = 3;
  auto frames = testing::make_ict_face_video(data / "ict-facekit", vo);
  ASSERT_TRUE(frames.is_ok()) << frames.status().message();
  const SequenceInfo info = testing::info_for(*frames);
  EncoderOptions on;
  on.preset = Preset::kSlow;
  on.intra_only = true;
  on.qp = 12;
  on.resolution = Resolution::kFull;  // the quadratic mode alone
  EncoderOptions off = on;
  off.quadratic_intra = false;
  const std::string a = testing::writer_round_trip(*frames, info, on);
  const std::string b = testing::writer_round_trip(*frames, info, off);
  EXPECT_LT(a.size(), b.size());
  EXPECT_GT(testing::stream_psnr_db(*frames, info, a),
            testing::stream_psnr_db(*frames, info, b) - 0.05);
  for (const auto& [type, flags] : testing::payload_flags(b))
    EXPECT_EQ(flags & format::kPayloadQuadraticIntra, 0);
}

}  // namespace
}  // namespace gvkit::codec
