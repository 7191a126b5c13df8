// The real SLStudio skull (2x3 scheme) reconstructs into a plausible surface: a skull-sized
// object with a locally smooth surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "gvkit/capture/fringe_folder.hpp"
#include "gvkit/capture/reconstructor.hpp"
#include "gvkit/core/calibration_io.hpp"
#include "support/test_support.hpp"

namespace gvkit::capture {
namespace {

TEST(SkullReconstruction, PlausibleSizeAndSmoothSurface) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  const auto dir = data / "slstudio-skull-2x3";
  auto calibration = read_calibration(dir / "calibration.xml");
  ASSERT_TRUE(calibration) << calibration.status().message();
  auto patterns = create_pattern_set("mf3-f16-f1");
  ASSERT_TRUE(patterns);
  auto folder = list_fringe_folder(dir, (*patterns)->image_count());
  ASSERT_TRUE(folder) << folder.status().message();
  ASSERT_EQ(folder->frames.size(), 1u);
  auto fringes = read_fringe_frame(*folder, 0);
  ASSERT_TRUE(fringes);
  auto scan = reconstruct(*fringes, **patterns, calibration->calibration);
  ASSERT_TRUE(scan) << scan.status().message();
  ASSERT_TRUE(scan->check());

  // The skull: the largest 8-connected valid region.
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(scan->valid, labels, stats, centroids, 8);
  ASSERT_GT(n, 1);
  int skull = 1;
  for (int i = 2; i < n; ++i)
    if (stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(skull, cv::CC_STAT_AREA)) skull = i;
  EXPECT_GT(stats.at<int>(skull, cv::CC_STAT_AREA), 150000);
  std::vector<float> xs, ys, zs, roughness;
  for (int y = 2; y + 2 < labels.rows; ++y)
    for (int x = 2; x + 2 < labels.cols; ++x) {
      if (labels.at<int>(y, x) != skull) continue;
      const cv::Vec3f p = scan->xyz_mm.at<cv::Vec3f>(y, x);
      xs.push_back(p[0]);
      ys.push_back(p[1]);
      zs.push_back(p[2]);
      // Local smoothness: distance from the mean of the 4-neighbours when all are valid.
      if ((y % 3) || (x % 3)) continue;
      const cv::Vec3f a = scan->xyz_mm.at<cv::Vec3f>(y, x - 1),
                      b = scan->xyz_mm.at<cv::Vec3f>(y, x + 1),
                      c = scan->xyz_mm.at<cv::Vec3f>(y - 1, x),
                      d = scan->xyz_mm.at<cv::Vec3f>(y + 1, x);
      if (std::isnan(a[2] + b[2] + c[2] + d[2])) continue;
      roughness.push_back(static_cast<float>(cv::norm(p - 0.25f * (a + b + c + d))));
    }
  auto spread = [](std::vector<float> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() * 99 / 100] - v[v.size() / 100];
  };
  // About 200 mm tall; a head is ~130-160 mm wide and deep.
  EXPECT_GT(spread(ys), 150.0f);
  EXPECT_LT(spread(ys), 260.0f);
  EXPECT_GT(spread(xs), 100.0f);
  EXPECT_LT(spread(xs), 220.0f);
  EXPECT_GT(spread(zs), 40.0f);
  EXPECT_LT(spread(zs), 250.0f);
  std::nth_element(roughness.begin(), roughness.begin() + roughness.size() / 2, roughness.end());
  EXPECT_LT(roughness[roughness.size() / 2], 0.3f) << "median deviation from neighbours (mm)";
}

}  // namespace
}  // namespace gvkit::capture
