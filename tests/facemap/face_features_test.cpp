// Lifting landmarks to 3D through a range scan.
#include "gvkit/facemap/face_features.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace gvkit::facemap {
namespace {

RangeScan plane_scan(int n) {
  RangeScan scan;
  scan.xyz_mm = cv::Mat(n, n, CV_32FC3);
  scan.texture = cv::Mat(n, n, CV_32F, cv::Scalar(0.5f));
  scan.valid = cv::Mat(n, n, CV_8U, cv::Scalar(255));
  scan.quality = cv::Mat(n, n, CV_32F, cv::Scalar(1.0f));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      scan.xyz_mm.at<cv::Vec3f>(y, x) = {static_cast<float>(x), static_cast<float>(y), 600.0f + x};
  return scan;
}

FaceLandmarks grid_landmarks() {
  FaceLandmarks l;
  for (int i = 0; i < FaceLandmarks::kCount; ++i)
    l.points_px.emplace_back(10.25f + (i % 10) * 20.0f, 10.5f + (i / 10) * 20.0f);
  return l;
}

TEST(FaceFeatures, LiftsBilinearly) {
  const RangeScan scan = plane_scan(256);
  FaceLandmarks l = grid_landmarks();
  ASSERT_TRUE(lift_landmarks(scan, &l).is_ok());
  for (int i = 0; i < FaceLandmarks::kCount; ++i) {
    EXPECT_NEAR(l.points_mm[i][0], l.points_px[i].x, 1e-4);
    EXPECT_NEAR(l.points_mm[i][1], l.points_px[i].y, 1e-4);
    EXPECT_NEAR(l.points_mm[i][2], 600.0 + l.points_px[i].x, 1e-3);
  }
}

TEST(FaceFeatures, RequiredLandmarkOutsideTheValidScanIsAnError) {
  RangeScan scan = plane_scan(256);
  FaceLandmarks l = grid_landmarks();
  // Invalidate a wide area around landmark 37 (an eye point).
  const cv::Point p = l.points_px[37];
  scan.valid(cv::Rect(p.x - 8, p.y - 8, 17, 17)).setTo(0);
  auto status = lift_landmarks(scan, &l);
  ASSERT_FALSE(status.is_ok());
  EXPECT_NE(status.message().find("landmark 37"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("outside the valid scan"), std::string::npos);
}

TEST(FaceFeatures, JawLandmarkOffTheScanTakesTheNearestValidPixel) {
  RangeScan scan = plane_scan(256);
  FaceLandmarks l = grid_landmarks();
  const cv::Point p = l.points_px[3];
  scan.valid(cv::Rect(p.x - 8, p.y - 8, 17, 17)).setTo(0);
  ASSERT_TRUE(lift_landmarks(scan, &l).is_ok());
  EXPECT_GT(std::hypot(l.points_mm[3][0] - l.points_px[3].x, l.points_mm[3][1] - l.points_px[3].y),
            7.0);
}

}  // namespace
}  // namespace gvkit::facemap
