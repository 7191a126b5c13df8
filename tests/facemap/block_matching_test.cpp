#include "gvkit/facemap/block_matching.hpp"

#include <gtest/gtest.h>

#include "gvkit/facemap/map_metrics.hpp"

namespace gvkit::facemap {
namespace {

GeometryImage smooth_image(int shift_x) {
  GeometryImage g;
  g.xyz_mm = cv::Mat(64, 64, CV_32FC3);
  g.domain_mask = cv::Mat(64, 64, CV_8U, cv::Scalar(255));
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const float u = static_cast<float>(x - shift_x);
      g.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(u, y, 0.01f * (u * u + y * y));
    }
  return g;
}

TEST(BlockMatching, FindsAPureShift) {
  auto e = block_matching_error(smooth_image(0), smooth_image(3));
  ASSERT_TRUE(e.is_ok());
  EXPECT_GT(e->zero_motion_mean_mse_mm2, 1.0);
  // Interior blocks find the shift exactly; the left border blocks cannot look outside.
  EXPECT_LT(e->mean_mse_mm2, 0.2 * e->zero_motion_mean_mse_mm2);
  auto same = block_matching_error(smooth_image(2), smooth_image(2));
  ASSERT_TRUE(same.is_ok());
  EXPECT_EQ(same->mean_mse_mm2, 0.0);
}

TEST(BlockMatching, RejectsMismatchedImagesAndBadOptions) {
  GeometryImage small = smooth_image(0);
  small.xyz_mm = small.xyz_mm(cv::Rect(0, 0, 32, 32)).clone();
  small.domain_mask = small.domain_mask(cv::Rect(0, 0, 32, 32)).clone();
  EXPECT_FALSE(block_matching_error(small, smooth_image(0)).is_ok());
  BlockMatchingOptions bad;
  bad.block_size = 0;
  EXPECT_FALSE(block_matching_error(smooth_image(0), smooth_image(0), bad).is_ok());
}

TEST(MapQuality, IsometryIsOneAndFlipsAreCounted) {
  std::vector<Eigen::Vector3d> xyz = {{0, 0, 5}, {2, 0, 5}, {0, 2, 5},
                                      {0, 0, 5}, {2, 0, 5}, {0, 2, 5}};
  std::vector<Eigen::Vector2d> uv = {{0, 0}, {4, 0}, {0, 4}, {0, 0}, {0, 4}, {4, 0}};
  const MapQuality q = measure_map_quality(xyz, uv, +1);
  EXPECT_EQ(q.triangles, 2);
  EXPECT_EQ(q.flipped, 1);
  EXPECT_NEAR(q.eps_angle, 1.0, 1e-12);  // a similarity: no angle or (normalized) area change
  EXPECT_NEAR(q.eps_area, 1.0, 1e-12);
  std::vector<Eigen::Vector2d> sheared = {{0, 0}, {4, 0}, {3, 1}};
  const MapQuality s = measure_map_quality({xyz[0], xyz[1], xyz[2]}, sheared, +1);
  EXPECT_GT(s.eps_angle, 1.5);
}

}  // namespace
}  // namespace gvkit::facemap
