// Lifting landmarks to 3D through a range scan; the eye and mouth openings of a scan's mesh.
#include "gvkit/facemap/face_features.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "gvkit/facemap/mesh_from_scan.hpp"

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

// Places the contour's landmarks on an ellipse around (cx, cy) px.
template <size_t N>
void ellipse_contour(FaceLandmarks* l, const std::array<int, N>& ids, float cx, float cy, float rx,
                     float ry) {
  for (size_t k = 0; k < N; ++k) {
    const double a = 2.0 * std::numbers::pi * static_cast<double>(k) / N;
    l->points_px[ids[k]] = cv::Point2f(cx + rx * static_cast<float>(std::cos(a)),
                                       cy + ry * static_cast<float>(std::sin(a)));
  }
}

TEST(FaceFeatures, FeatureInteriorHolesAreTheOpeningsInsideTheContours) {
  RangeScan scan = plane_scan(256);
  FaceLandmarks l = grid_landmarks();
  ellipse_contour(&l, kRightEyeContour, 60, 60, 14, 6);
  ellipse_contour(&l, kLeftEyeContour, 140, 60, 14, 6);
  ellipse_contour(&l, kInnerMouthContour, 100, 150, 20, 7);
  int removed = 0;
  scan.valid = valid_without_feature_interiors(scan, l, 0.5, &removed);
  ASSERT_GT(removed, 300);
  // A scan gap away from the features, and one that merges with the left eye's opening and
  // reaches 10 px beyond its contour: neither is an opening inside a contour.
  scan.valid(cv::Rect(200, 200, 6, 6)).setTo(0);
  scan.valid(cv::Rect(140, 58, 25, 5)).setTo(0);
  auto mesh = mesh_from_scan(scan);
  ASSERT_TRUE(mesh.is_ok()) << mesh.status().message();
  const auto holes = feature_interior_holes(mesh->mesh, mesh->vertex_pixel, l);
  ASSERT_EQ(holes.size(), 2u);
  std::vector<int> features;
  for (const auto& h : holes) {
    EXPECT_TRUE(mesh->mesh.is_boundary(h.halfedge));
    features.push_back(h.feature);
    // Every vertex of the loop lies inside (or at the edge of) its contour.
    const auto& ids = h.feature == 0
                          ? std::vector<int>(kRightEyeContour.begin(), kRightEyeContour.end())
                          : std::vector<int>(kInnerMouthContour.begin(), kInnerMouthContour.end());
    std::vector<cv::Point2f> contour;
    for (int i : ids) contour.push_back(l.points_px[i]);
    auto e = h.halfedge;
    do {
      const cv::Point p = mesh->vertex_pixel[mesh->mesh.to_vertex_handle(e).idx()];
      EXPECT_GE(cv::pointPolygonTest(contour, cv::Point2f(p), true), -2.0);
      e = mesh->mesh.next_halfedge_handle(e);
    } while (e != h.halfedge);
  }
  std::sort(features.begin(), features.end());
  EXPECT_EQ(features, (std::vector<int>{0, 2}));
}

}  // namespace
}  // namespace gvkit::facemap
