#include "gvkit/player/manifold_verdict_cache.hpp"

#include <atomic>
#include <random>
#include <thread>

#include <gtest/gtest.h>

namespace gvkit::player {
namespace {

// A w x h geometry image over a random domain (holes, scattered missing pixels) whose depths are
// random, so frames of the same domain split their quads along different diagonals.
GeometryImage random_frame(int w, int h, const cv::Mat& mask, std::mt19937& rng) {
  std::uniform_real_distribution<float> depth(0.0f, 4.0f);
  GeometryImage image;
  image.xyz_mm.create(h, w, CV_32FC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      image.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(2.0f * x, 2.0f * y, 100.0f + depth(rng));
  image.domain_mask = mask.clone();
  return image;
}

// Over random domains, each meshed in several frames: the cached verdict is the check's on every
// frame, although the frames' triangles differ (their diagonals), and the check runs once per
// domain; with max_edge_mm (triangles dropped by the geometry) it runs every time. Both verdicts
// occur.
TEST(ManifoldVerdictCache, OneCheckPerDomainAndTheVerdictOfEveryFrame) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int manifold = 0, not_manifold = 0, differing_triangles = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int w = 6 + trial % 11, h = 5 + trial % 9;
    cv::Mat mask(h, w, CV_8U, cv::Scalar(255));
    const double keep = 0.5 + 0.5 * unit(rng);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (unit(rng) > keep) mask.at<uint8_t>(y, x) = 0;
    GeometryImageMeshOptions options;
    options.partial_quads = trial % 3 != 0;
    options.stride = trial % 4 == 0 ? 2 : 1;
    ManifoldVerdictCache cache;
    std::vector<uint32_t> first_indices;
    for (int frame = 0; frame < 4; ++frame) {
      const MeshBuffers b =
          mesh_buffers_from_geometry_image(random_frame(w, h, mask, rng), options);
      const bool expected = mesh_buffers_manifold(b);
      ASSERT_EQ(cache.manifold(b, options), expected) << "trial " << trial << " frame " << frame;
      (expected ? manifold : not_manifold) += 1;
      if (frame == 0) first_indices = b.indices;
      if (frame > 0 && b.indices != first_indices) ++differing_triangles;
    }
    EXPECT_EQ(cache.checks(), 1) << "trial " << trial;

    options.max_edge_mm = 2.5;  // drops some of the 2 mm grid's diagonals, depending on depth
    ManifoldVerdictCache dropping;
    for (int frame = 0; frame < 3; ++frame) {
      const MeshBuffers b =
          mesh_buffers_from_geometry_image(random_frame(w, h, mask, rng), options);
      ASSERT_EQ(dropping.manifold(b, options), mesh_buffers_manifold(b)) << "trial " << trial;
    }
    EXPECT_EQ(dropping.checks(), 3);
  }
  EXPECT_GT(manifold, 100);
  EXPECT_GT(not_manifold, 100);
  EXPECT_GT(differing_triangles, 300);
}

// Another domain, size or option is checked again.
TEST(ManifoldVerdictCache, AnotherDomainOrOptionIsCheckedAgain) {
  std::mt19937 rng(5);
  cv::Mat full(8, 9, CV_8U, cv::Scalar(255));
  cv::Mat holed = full.clone();
  holed.at<uint8_t>(4, 4) = 0;
  ManifoldVerdictCache cache;
  GeometryImageMeshOptions options;
  EXPECT_TRUE(
      cache.manifold(mesh_buffers_from_geometry_image(random_frame(9, 8, full, rng)), options));
  EXPECT_EQ(cache.checks(), 1);
  cache.manifold(mesh_buffers_from_geometry_image(random_frame(9, 8, holed, rng)), options);
  EXPECT_EQ(cache.checks(), 2);
  GeometryImageMeshOptions whole_quads;
  whole_quads.partial_quads = false;
  cache.manifold(mesh_buffers_from_geometry_image(random_frame(9, 8, holed, rng), whole_quads),
                 whole_quads);
  EXPECT_EQ(cache.checks(), 3);
  cache.manifold(mesh_buffers_from_geometry_image(random_frame(9, 8, holed, rng), whole_quads),
                 whole_quads);
  EXPECT_EQ(cache.checks(), 3);
}

TEST(ManifoldVerdictCache, WorkersShareTheVerdict) {
  std::mt19937 rng(9);
  const cv::Mat mask(12, 12, CV_8U, cv::Scalar(255));
  const MeshBuffers b = mesh_buffers_from_geometry_image(random_frame(12, 12, mask, rng));
  ManifoldVerdictCache cache;
  std::vector<std::thread> workers;
  std::atomic<int> wrong{0};
  for (int t = 0; t < 4; ++t)
    workers.emplace_back([&] {
      for (int k = 0; k < 200; ++k)
        if (!cache.manifold(b, {})) ++wrong;
    });
  for (std::thread& w : workers) w.join();
  EXPECT_EQ(wrong.load(), 0);
  EXPECT_GE(cache.checks(), 1);
  EXPECT_LE(cache.checks(), 4);  // at most one per worker racing at the start
}

}  // namespace
}  // namespace gvkit::player
