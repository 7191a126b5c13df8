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

// A plane z = 0 sampled 1 mm apart, moved by `dz` mm along z in the rows from `moving_from` on.
GeometryImage stepped_plane(int moving_from, float dz) {
  GeometryImage g;
  g.xyz_mm = cv::Mat(32, 64, CV_32FC3);
  g.domain_mask = cv::Mat(32, 64, CV_8U, cv::Scalar(255));
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x)
      g.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(x, y, y >= moving_from ? dz : 0.0f);
  return g;
}

TEST(BlockMatching, AreaWeightingCountsSurfaceNotPixels) {
  // The lower half moves 1 mm out of the plane: no displacement within the image can match it,
  // so it keeps an error of 1 mm^2 in Z, a third of the mean over X, Y, Z.
  const auto even = block_matching_error(stepped_plane(16, 0), stepped_plane(16, 1));
  ASSERT_TRUE(even.is_ok());
  EXPECT_NEAR(even->mean_mse_mm2, 0.5 / 3, 1e-6);
  // (The step's own row samples a slanted strip, a little more area: hence the tolerance.)
  EXPECT_NEAR(even->area_weighted_mean_mse_mm2, 0.5 / 3, 0.01);
  // The same surface and motion with the moving half sampled by three times as many rows (rows
  // 0-7 cover the still half at 2 mm per row, rows 8-31 the moving half at 2/3 mm per row):
  // the plain MSE triples its moving share, the error per area stays.
  GeometryImage still, moved;
  for (auto* g : {&still, &moved}) {
    *g = stepped_plane(8, g == &moved ? 1.0f : 0.0f);
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 64; ++x)
        g->xyz_mm.at<cv::Vec3f>(y, x)[1] = y < 8 ? 2.0f * y : 16 + (y - 8) * 2.0f / 3;
  }
  const auto dense = block_matching_error(still, moved);
  ASSERT_TRUE(dense.is_ok());
  EXPECT_NEAR(dense->mean_mse_mm2, 0.75 / 3, 1e-6);
  EXPECT_NEAR(dense->area_weighted_mean_mse_mm2, 0.5 / 3, 0.01);
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

// A smooth surface with noise over an elliptic domain with a hole, moved by (shift_x, shift_y)
// px, `missing` pixels of it left out at random, in a view of a larger image (rows not contiguous).
GeometryImage noisy_face(cv::Size size, int shift_x, int shift_y, int missing, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat xyz(size.height + 4, size.width + 7, CV_32FC3), mask(xyz.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < xyz.rows; ++y)
    for (int x = 0; x < xyz.cols; ++x) {
      const float u = static_cast<float>(x - shift_x), v = static_cast<float>(y - shift_y);
      xyz.at<cv::Vec3f>(y, x) =
          cv::Vec3f(0.7f * u, 0.7f * v, 0.004f * (u * u + 2 * v * v) + rng.uniform(-0.3f, 0.3f));
    }
  // An ellipse around the centre without a disc right of the centre.
  const double cx = size.width / 2.0 + shift_x, cy = size.height / 2.0 + shift_y;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x) {
      const double ex = (x - cx) / (0.4 * size.width), ey = (y - cy) / (0.45 * size.height);
      const double hx = x - cx - size.width / 8.0, hy = y - cy, hr = size.width / 12.0;
      if (ex * ex + ey * ey <= 1 && hx * hx + hy * hy > hr * hr) mask.at<uint8_t>(y, x) = 255;
    }
  for (int k = 0; k < missing; ++k)  // scattered missing pixels
    mask.at<uint8_t>(rng.uniform(0, mask.rows), rng.uniform(0, mask.cols)) = 0;
  const cv::Rect view(3, 2, size.width, size.height);
  GeometryImage g;
  g.xyz_mm = xyz(view);
  g.domain_mask = mask(view);
  return g;
}

TEST(BlockMatching, TheAvx2PathGivesTheReferenceFigures) {
  struct Case {
    cv::Size size;
    BlockMatchingOptions options;
  };
  BlockMatchingOptions wide;
  wide.block_size = 70;  // more than the 64 pixels of one mask word
  wide.search_range = 5;
  BlockMatchingOptions narrow;
  narrow.block_size = 5;
  narrow.search_range = 3;
  const std::vector<Case> cases = {
      {{96, 80}, {}}, {{101, 83}, {}}, {{150, 141}, wide}, {{37, 29}, narrow}};
  for (const Case& c : cases)
    for (int seed = 1; seed <= 3; ++seed) {
      const GeometryImage a = noisy_face(c.size, 0, 0, 2, seed);
      const GeometryImage b = noisy_face(c.size, 3, -2, 30, seed + 10);
      const auto fast = block_matching_error(a, b, c.options);
      const auto plain = block_matching_error_reference(a, b, c.options);
      ASSERT_TRUE(fast.is_ok() && plain.is_ok());
      SCOPED_TRACE(::testing::Message() << c.size << " block " << c.options.block_size);
      EXPECT_LT(plain->mean_mse_mm2, plain->zero_motion_mean_mse_mm2);  // the search matters
      for (int k = 0; k < 3; ++k) EXPECT_EQ(fast->mse_mm2[k], plain->mse_mm2[k]);
      EXPECT_EQ(fast->mean_mse_mm2, plain->mean_mse_mm2);
      EXPECT_EQ(fast->zero_motion_mean_mse_mm2, plain->zero_motion_mean_mse_mm2);
      EXPECT_EQ(fast->area_weighted_mean_mse_mm2, plain->area_weighted_mean_mse_mm2);
    }
}

TEST(MapMetrics, CarriedImageSamplesTheSameSurfacePoints) {
  // Frame a: a 2 x 2 image whose pixels sample vertices 0-2 (pixel 3 was filled from its
  // neighbours, without a sample of its own).
  MappedFace a;
  a.image.xyz_mm = cv::Mat(2, 2, CV_32FC3, cv::Scalar::all(0));
  a.image.domain_mask = cv::Mat(2, 2, CV_8U, cv::Scalar(255));
  a.image.index = 4;
  a.pixel_source = {{{0, 1.0}}, {{1, 0.5}, {2, 0.5}}, {{2, 1.0}}, {}};
  const std::vector<cv::Vec3d> b = {{1, 2, 3}, {10, 0, 0}, {0, 10, 4}};
  const GeometryImage carried = carried_geometry_image(a, b);
  EXPECT_EQ(carried.index, 4);
  EXPECT_EQ(carried.xyz_mm.at<cv::Vec3f>(0, 0), cv::Vec3f(1, 2, 3));
  EXPECT_EQ(carried.xyz_mm.at<cv::Vec3f>(0, 1), cv::Vec3f(5, 5, 2));
  EXPECT_EQ(carried.xyz_mm.at<cv::Vec3f>(1, 0), cv::Vec3f(0, 10, 4));
  EXPECT_EQ(carried.domain_mask.at<uint8_t>(0, 1), 255);
  EXPECT_EQ(carried.domain_mask.at<uint8_t>(1, 1), 0);  // nothing to carry
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
