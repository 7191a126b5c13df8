// The P-frame and bounded-error tools end to end: near-lossless coding with a guaranteed point
// error (on the ICT face when the shared data is present, and on the analytic surface),
// value-domain prediction of rigidly moving geometry, per-plane QP offsets, rate control with a
// bounded buffer, and multithreaded encoding that writes the same bytes as one thread.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "geometry_video_material.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/value_prediction.hpp"
#include "support/test_support.hpp"

namespace gvkit::codec {
namespace {

SequenceInfo info_for(const std::vector<GeometryImage>& frames, int bit_depth = 16) {
  auto info = make_sequence_info(frames, bit_depth, 30.0);
  GVKIT_CHECK(info.is_ok(), info.status().message());
  return std::move(info).value();
}

std::vector<GeometryImage> analytic_video(int size, int frames) {
  testing::GeometryVideoOptions o;
  o.size = size;
  o.frames = frames;
  return testing::make_analytic_video(o);
}

// Encodes, decodes every frame with a GvidReader and returns the largest point error of any
// domain pixel of any frame against the input; *bytes_out gets the stream size.
double max_point_error(const std::vector<GeometryImage>& frames, const SequenceInfo& info,
                       const EncoderOptions& options, size_t* bytes_out) {
  auto bytes = encode_gvid(frames, info, options);
  EXPECT_TRUE(bytes.is_ok()) << bytes.status().message();
  if (!bytes.is_ok()) return INFINITY;
  *bytes_out = bytes->size();
  auto reader = GvidReader::open_memory(*bytes, "test.gvid");
  EXPECT_TRUE(reader.is_ok());
  double max_mm = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    auto decoded = (*reader)->decode_frame(static_cast<int64_t>(f));
    EXPECT_TRUE(decoded.is_ok()) << decoded.status().message();
    if (!decoded.is_ok()) return INFINITY;
    max_mm = std::max(max_mm, geometry_error(frames[f], *decoded).max_mm);
  }
  return max_mm;
}

void expect_bound_holds(const std::vector<GeometryImage>& frames, Preset preset, int bit_depth) {
  const SequenceInfo info = info_for(frames, bit_depth);
  EncoderOptions lossless;
  lossless.lossless = true;
  lossless.bit_depth = bit_depth;
  lossless.preset = preset;
  lossless.intra_period = 3;
  size_t lossless_bytes = 0;
  max_point_error(frames, info, lossless, &lossless_bytes);
  size_t previous_bytes = lossless_bytes;
  // Bounds from a few input quantization errors (sqrt(3) step) up to a coarse one.
  for (double k : {3.0, 10.0, 40.0, 150.0}) {
    const double bound_mm = k * std::sqrt(3.0) * info.step_mm();
    EncoderOptions o = lossless;
    o.lossless = false;
    o.max_error_mm = bound_mm;
    size_t bytes = 0;
    const double max_mm = max_point_error(frames, info, o, &bytes);
    EXPECT_LE(max_mm, bound_mm) << "bound " << bound_mm << " mm at " << bit_depth << " bits";
    // The bound is used, not just met by coding exactly: the error reaches a good part of it.
    EXPECT_GT(max_mm, 0.4 * bound_mm) << "bound " << bound_mm << " mm";
    EXPECT_LT(bytes, previous_bytes) << "bound " << bound_mm << " mm";
    previous_bytes = bytes;
  }
}

TEST(InterTools, MaxErrorBoundHoldsOnEveryPixelOfTheAnalyticSurface) {
  expect_bound_holds(analytic_video(48, 4), Preset::kFast, 16);
  expect_bound_holds(analytic_video(32, 3), Preset::kSlow, 16);
  expect_bound_holds(analytic_video(32, 3), Preset::kFast, 12);
}

TEST(InterTools, MaxErrorBoundHoldsOnEveryPixelOfTheIctFace) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  testing::GeometryVideoOptions o;
  o.size = 96;
  o.frames = 4;
  auto frames = testing::make_ict_face_video(data / "ict-facekit", o);
  ASSERT_TRUE(frames.is_ok()) << frames.status().message();
  expect_bound_holds(*frames, Preset::kFast, 16);
}

TEST(InterTools, MaxErrorBelowTheQuantizationIsRejected) {
  const auto frames = analytic_video(32, 2);
  const SequenceInfo info = info_for(frames, 8);
  EncoderOptions o;
  o.bit_depth = 8;
  o.max_error_mm = info.step_mm() * 0.5;
  auto bytes = encode_gvid(frames, info, o);
  ASSERT_FALSE(bytes.is_ok());
  EXPECT_NE(bytes.status().message().find("raise --bit-depth"), std::string::npos);
  o.lossless = true;
  EXPECT_NE(o.check().message().find("exclude"), std::string::npos);
}

// Frame k is frame 0 turned by k degrees about a vertical axis and shifted by k mm: a rigid head
// motion that changes every xyz sample while the picture stays put.
std::vector<GeometryImage> rigidly_moving_video(int frames) {
  const std::vector<GeometryImage> base = analytic_video(64, 1);
  std::vector<GeometryImage> out;
  for (int k = 0; k < frames; ++k) {
    GeometryImage g = base[0];
    g.xyz_mm = base[0].xyz_mm.clone();
    g.index = k;
    const double a = k * M_PI / 180.0;
    g.xyz_mm.forEach<cv::Vec3f>([&](cv::Vec3f& p, const int*) {
      const double x = p[0], z = p[2];
      p[0] = static_cast<float>(std::cos(a) * x + std::sin(a) * z + k);
      p[1] = static_cast<float>(p[1] + 0.5 * k);
      p[2] = static_cast<float>(-std::sin(a) * x + std::cos(a) * z);
    });
    out.push_back(std::move(g));
  }
  return out;
}

TEST(InterTools, AffineValuePredictionFollowsRigidMotionAndStaysLossless) {
  const auto frames = rigidly_moving_video(4);
  const SequenceInfo info = info_for(frames);
  size_t sizes[4] = {};
  for (ValuePrediction mode : {ValuePrediction::kNone, ValuePrediction::kOffset,
                               ValuePrediction::kWeighted, ValuePrediction::kAffine}) {
    EncoderOptions o;
    o.lossless = true;
    o.preset = Preset::kFast;
    o.value_prediction = mode;
    auto bytes = encode_gvid(frames, info, o);
    ASSERT_TRUE(bytes.is_ok()) << bytes.status().message();
    sizes[static_cast<int>(mode)] = bytes->size();
    auto reader = GvidReader::open_memory(*bytes, "test.gvid");
    ASSERT_TRUE(reader.is_ok());
    for (int f = 0; f < 4; ++f) {
      const GeometryImage expected =
          dequantize_geometry(quantize_geometry(frames[f], info), info, f);
      auto decoded = (*reader)->decode_frame(f);
      ASSERT_TRUE(decoded.is_ok()) << decoded.status().message();
      EXPECT_EQ(geometry_error(expected, *decoded).max_mm, 0.0)
          << value_prediction_name(mode) << " frame " << f;
    }
  }
  // The rotation mixes x and z: only the full affine map predicts it well.
  EXPECT_LT(sizes[3], sizes[0] * 8 / 10);
  EXPECT_LT(sizes[3], sizes[1]);
  EXPECT_LT(sizes[3], sizes[2]);
}

TEST(InterTools, ValueTransformFitRecoversAKnownMap) {
  const auto frames = rigidly_moving_video(1);
  const SequenceInfo info = info_for(frames);
  const std::vector<SamplePlane> ref = quantize_geometry(frames[0], info);
  ValueTransform truth;
  truth.m[0][0] = 64000;
  truth.m[0][2] = 3000;
  truth.m[2][0] = -3000;
  truth.t[1] = 5 * 65536;
  const std::vector<SamplePlane> cur = apply_value_transform(ref, truth, 16);
  const ValueTransform fit =
      fit_value_transform(cur, ref, info.domain_mask, ValuePrediction::kAffine, 16);
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) EXPECT_NEAR(fit.m[a][b], truth.m[a][b], 40) << a << b;
    EXPECT_NEAR(fit.t[a], truth.t[a], 65536);
  }
  // And the syntax round-trips.
  ByteWriter w;
  write_value_transform(w, fit);
  const std::string bytes = w.str();  // ByteReader views it: keep it alive
  ByteReader r(bytes);
  auto back = read_value_transform(r);
  ASSERT_TRUE(back.is_ok());
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(back->t[a], fit.t[a]);
    for (int b = 0; b < 3; ++b) EXPECT_EQ(back->m[a][b], fit.m[a][b]);
  }
  const std::string head = bytes.substr(0, 5);
  ByteReader truncated(head);
  EXPECT_FALSE(read_value_transform(truncated).is_ok());
}

TEST(InterTools, PlaneQpOffsetsChangeThatPlanesErrorOnly) {
  const auto frames = analytic_video(48, 2);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.qp = 0;
  o.preset = Preset::kFast;
  o.plane_qp_offset[2] = 12;  // Z coarser
  auto bytes = encode_gvid(frames, info, o);
  ASSERT_TRUE(bytes.is_ok()) << bytes.status().message();
  auto reader = GvidReader::open_memory(*bytes, "test.gvid");
  ASSERT_TRUE(reader.is_ok());
  for (int f = 0; f < 2; ++f) {
    auto decoded = (*reader)->decode_frame(f);
    ASSERT_TRUE(decoded.is_ok()) << decoded.status().message();
    double err[3] = {0, 0, 0};
    for (int y = 0; y < info.height; ++y)
      for (int x = 0; x < info.width; ++x) {
        if (!info.domain_mask.at<uint8_t>(y, x)) continue;
        const cv::Vec3f d =
            frames[f].xyz_mm.at<cv::Vec3f>(y, x) - decoded->xyz_mm.at<cv::Vec3f>(y, x);
        for (int a = 0; a < 3; ++a) err[a] += d[a] * d[a];
      }
    EXPECT_GT(err[2], 4 * err[0]) << "frame " << f;
    EXPECT_GT(err[2], 4 * err[1]) << "frame " << f;
  }
  o.plane_qp_offset[0] = 13;
  EXPECT_NE(o.check().message().find("plane QP offset"), std::string::npos);
}

TEST(InterTools, RateControlMeetsTheTargetWithinTheBuffer) {
  const auto frames = analytic_video(64, 24);
  const SequenceInfo info = info_for(frames);
  for (double kbps : {150.0, 600.0}) {
    EncoderOptions o;
    o.preset = Preset::kFast;
    o.intra_period = 12;
    o.bitrate_kbps = kbps;
    o.buffer_seconds = 0.5;
    std::vector<SamplePlane> reference;
    RateController rate(o, info.fps);
    int64_t bits = 0;
    for (size_t i = 0; i < frames.size(); ++i) {
      auto e =
          encode_sequence_frame(frames[i], info, o, static_cast<uint32_t>(i), reference, &rate);
      ASSERT_TRUE(e.is_ok()) << e.status().message();
      reference = e->planes;
      bits += static_cast<int64_t>(e->packet.size()) * 8;
      EXPECT_LE(rate.fullness_bits(), rate.buffer_bits()) << kbps << " kbit/s, frame " << i;
    }
    const double achieved_kbps = bits / (frames.size() / info.fps) / 1000.0;
    // Within the buffer's worth of bits of the target over the whole run.
    EXPECT_NEAR(achieved_kbps, kbps, o.buffer_seconds * kbps / (frames.size() / info.fps))
        << kbps << " kbit/s";
  }
}

TEST(InterTools, ThreadsWriteTheSameBytesAsOneThread) {
  const auto frames = analytic_video(48, 3);
  const SequenceInfo info = info_for(frames);
  EncoderOptions configs[3];
  configs[0].qp = 0;
  configs[0].preset = Preset::kFast;
  configs[1].max_error_mm = 0.05;
  configs[1].value_prediction = ValuePrediction::kAffine;
  configs[2].lossless = true;
  configs[2].preset = Preset::kFast;
  for (const EncoderOptions& base : configs) {
    EncoderOptions one = base, many = base;
    many.threads = 3;
    auto a = encode_gvid(frames, info, one);
    auto b = encode_gvid(frames, info, many);
    ASSERT_TRUE(a.is_ok() && b.is_ok());
    EXPECT_EQ(*a, *b);
  }
  EncoderOptions bad;
  bad.threads = 0;
  EXPECT_NE(bad.check().message().find("threads"), std::string::npos);
}

}  // namespace
}  // namespace gvkit::codec
