// The Draco peer of the rate-distortion bench (bench/codec/draco_peer.cpp): a small analytic
// geometry image through Draco's mesh and point-cloud coders comes back matched to its pixels
// with every point within the quantization bound, more bits buy less error, and bad options are
// rejected naming the option; the nearest-point grid that matches Draco's points back to the
// pixels equals a brute-force search.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "draco_peer.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "nearest_point_grid.hpp"

namespace gvkit::bench {
namespace {

TEST(DracoPeer, DecodedPointsLieWithinTheQuantizationStepBound) {
  testing::GeometryVideoOptions vo;
  vo.size = 40;
  vo.frames = 1;
  const auto frames = testing::make_analytic_video(vo);
  auto info = codec::make_sequence_info(frames, 16, vo.fps);
  ASSERT_TRUE(info.is_ok()) << info.status().message();
  double range = 0;
  for (int a = 0; a < 3; ++a) range = std::max(range, info->box_max_mm[a] - info->box_min_mm[a]);
  for (const DracoGeometry geometry : {DracoGeometry::kMesh, DracoGeometry::kPointCloud}) {
    double previous_rms = INFINITY;
    int64_t previous_bytes = 0;
    for (const int bits : {11, 14}) {
      DracoOptions o;
      o.geometry = geometry;
      o.quantization_bits = bits;
      auto r = draco_round_trip(frames[0], *info, o);
      ASSERT_TRUE(r.is_ok()) << r.status().message();
      EXPECT_EQ(r->input_points, info->domain_pixels());
      EXPECT_GE(r->decoded_points, r->input_points) << draco_geometry_name(geometry);
      // Rounding to a step of range / (2^bits - 1) moves each axis by at most half a step; the
      // nearest decoded point is no farther than the pixel's own.
      const double step = range / ((1 << bits) - 1);
      const codec::GeometryError e = codec::geometry_error(frames[0], r->decoded);
      EXPECT_EQ(e.pixels, info->domain_pixels());
      EXPECT_LE(e.max_mm, 0.5 * std::sqrt(3.0) * step * 1.0001)
          << draco_geometry_name(geometry) << ", " << bits << " bits";
      EXPECT_GT(e.max_mm, 0.0);
      EXPECT_LT(e.rms_mm, previous_rms);
      EXPECT_GT(r->bytes, previous_bytes);
      previous_rms = e.rms_mm;
      previous_bytes = r->bytes;
    }
  }
}

TEST(NearestPointGrid, EqualsABruteForceSearch) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-50.0f, 50.0f);
  std::vector<cv::Vec3f> points(2000);
  for (auto& p : points) p = {u(rng), u(rng), 0.1f * u(rng)};  // a flat slab, like a surface
  points.push_back(points[10]);                                // a duplicate: the lower index wins
  for (const double cell : {0.5, 3.0, 40.0}) {
    const NearestPointGrid grid(points, cell);
    for (int q = 0; q < 300; ++q) {
      // Queries inside, near and far outside the points' box.
      const float scale = q < 250 ? 1.0f : 2.0f;
      const cv::Vec3f p(scale * u(rng), scale * u(rng), scale * u(rng));
      int64_t best = -1;
      double best_d2 = INFINITY;
      for (size_t i = 0; i < points.size(); ++i) {
        const cv::Vec3d d = cv::Vec3d(points[i]) - cv::Vec3d(p);
        if (d.dot(d) < best_d2) {
          best_d2 = d.dot(d);
          best = static_cast<int64_t>(i);
        }
      }
      EXPECT_EQ(grid.nearest(p), best) << "cell " << cell << ", query " << q;
    }
    EXPECT_EQ(grid.nearest(points[10]), 10);
  }
  EXPECT_EQ(NearestPointGrid({}, 1.0).nearest({0, 0, 0}), -1);
}

TEST(DracoPeer, BadOptionsFailNamingTheOption) {
  DracoOptions o;
  o.quantization_bits = 0;
  EXPECT_NE(o.check().message().find("quantization bits 0"), std::string::npos);
  o.quantization_bits = 12;
  o.compression_level = 11;
  EXPECT_NE(o.check().message().find("compression level 11"), std::string::npos);
}

}  // namespace
}  // namespace gvkit::bench
