// Triangulation of known surfaces (plane, sphere) with lens distortion on both devices: the
// projector column each camera pixel sees is computed by ray casting and OpenCV's projection;
// the Reconstructor must recover the points. Fast and reference paths must agree.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include <opencv2/calib3d.hpp>

#include "gvkit/capture/reconstructor.hpp"
#include "gvkit/capture/synthetic_rig.hpp"

namespace gvkit::capture {
namespace {

Calibration distorted_rig() {
  SyntheticRigOptions o;
  o.camera_width = 80;
  o.camera_height = 64;
  o.camera_dist = {-0.12, 0.08, 0.001, -0.0015, 0.0};
  o.projector_dist = {0.06, -0.03, -0.0008, 0.0005, 0.0};
  return synthetic_calibration(o);
}

// Ray of camera pixel (x, y) (undistorted, z = 1).
cv::Vec3d camera_ray(const Calibration& c, int x, int y) {
  std::vector<cv::Point2d> in{{static_cast<double>(x), static_cast<double>(y)}}, out;
  cv::undistortPoints(in, out, c.camera_K, c.camera_dist, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-14));
  return {out[0].x, out[0].y, 1.0};
}

double projector_column_of(const Calibration& c, const cv::Vec3d& p) {
  cv::Vec3d rvec;
  cv::Rodrigues(c.R_proj_from_cam(), rvec);
  std::vector<cv::Point3d> in{cv::Point3d(p)};
  std::vector<cv::Point2d> out;
  cv::projectPoints(in, rvec, c.t_proj_from_cam_mm(), c.projector_K, c.projector_dist, out);
  return out[0].x;
}

// Ray casting against a surface; fills the column map and the true points.
template <typename Hit>
void cast(const Calibration& c, Hit hit, cv::Mat& u, cv::Mat& truth) {
  u = cv::Mat(c.camera_height, c.camera_width, CV_32F, cv::Scalar(NAN));
  truth = cv::Mat(c.camera_height, c.camera_width, CV_32FC3, cv::Scalar::all(NAN));
  for (int y = 0; y < c.camera_height; ++y)
    for (int x = 0; x < c.camera_width; ++x) {
      const cv::Vec3d d = camera_ray(c, x, y);
      const std::optional<double> s = hit(d);
      if (!s) continue;
      const cv::Vec3d p = d * *s;
      u.at<float>(y, x) = static_cast<float>(projector_column_of(c, p));
      truth.at<cv::Vec3f>(y, x) = cv::Vec3f(p);
    }
}

double max_error(const cv::Mat& xyz, const cv::Mat& truth, int* compared) {
  double worst = 0;
  *compared = 0;
  for (int y = 0; y < xyz.rows; ++y)
    for (int x = 0; x < xyz.cols; ++x) {
      const cv::Vec3f t = truth.at<cv::Vec3f>(y, x);
      if (std::isnan(t[2])) continue;
      const cv::Vec3f p = xyz.at<cv::Vec3f>(y, x);
      EXPECT_TRUE(std::isfinite(p[2])) << x << "," << y;
      worst = std::max(worst, static_cast<double>(cv::norm(p - t)));
      ++*compared;
    }
  return worst;
}

TEST(Triangulation, TiltedPlaneWithDistortion) {
  const Calibration c = distorted_rig();
  auto r = Reconstructor::create(c);
  ASSERT_TRUE(r) << r.status().message();
  // Plane n . X = 700 with a tilt.
  const cv::Vec3d n = cv::normalize(cv::Vec3d(0.2, -0.1, 1.0));
  cv::Mat u, truth;
  cast(
      c, [&](const cv::Vec3d& d) -> std::optional<double> { return 700.0 / n.dot(d); }, u, truth);
  int compared = 0;
  // float output at ~700 mm: a few micrometres.
  EXPECT_LT(max_error(r->triangulate_columns(u), truth, &compared), 0.01);
  EXPECT_EQ(compared, c.camera_width * c.camera_height);
}

TEST(Triangulation, SphereWithDistortionFastMatchesReference) {
  const Calibration c = distorted_rig();
  auto r = Reconstructor::create(c);
  ASSERT_TRUE(r);
  const cv::Vec3d centre(10, -5, 650);
  const double radius = 90;
  cv::Mat u, truth;
  cast(
      c,
      [&](const cv::Vec3d& d) -> std::optional<double> {
        // |s d - c|^2 = r^2, nearest root.
        const double a = d.dot(d), b = -2 * d.dot(centre),
                     cc = centre.dot(centre) - radius * radius;
        const double disc = b * b - 4 * a * cc;
        if (disc < 0) return std::nullopt;
        return (-b - std::sqrt(disc)) / (2 * a);
      },
      u, truth);
  int compared = 0;
  const cv::Mat fast = r->triangulate_columns(u);
  EXPECT_LT(max_error(fast, truth, &compared), 0.01);
  EXPECT_GT(compared, 1000);
  const cv::Mat reference = r->triangulate_columns_reference(u);
  EXPECT_LT(max_error(reference, truth, &compared), 0.01);
  for (int y = 0; y < u.rows; ++y)
    for (int x = 0; x < u.cols; ++x) {
      const cv::Vec3f a = fast.at<cv::Vec3f>(y, x), b = reference.at<cv::Vec3f>(y, x);
      if (std::isnan(a[2]) || std::isnan(b[2])) {
        EXPECT_EQ(std::isnan(a[2]), std::isnan(b[2])) << x << "," << y;
        continue;
      }
      ASSERT_LT(cv::norm(a - b), 0.01);
    }
}

TEST(Triangulation, NoDistortionFastPath) {
  Calibration c = synthetic_calibration();
  c.camera_width = 64;
  c.camera_height = 48;
  auto r = Reconstructor::create(c);
  ASSERT_TRUE(r);
  cv::Mat u, truth;
  cast(
      c, [](const cv::Vec3d& d) -> std::optional<double> { return 640.0; }, u, truth);
  int compared = 0;
  EXPECT_LT(max_error(r->triangulate_columns(u), truth, &compared), 0.01);
}

TEST(Triangulation, ParallelRaysAreRejected) {
  Calibration c = synthetic_calibration();
  // Projector straight above the camera, looking the same way: every vertical-fringe column
  // plane contains the baseline.
  c.R_cam_from_proj = cv::Matx33d::eye();
  c.t_cam_from_proj_mm = cv::Vec3d(0, -200, 0);
  auto r = Reconstructor::create(c);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(r.status().message().find("parallel"), std::string::npos) << r.status().message();
}

TEST(Triangulation, NonFiniteCalibrationIsRejected) {
  Calibration c = synthetic_calibration();
  c.projector_K(0, 0) = NAN;
  auto r = Reconstructor::create(c);
  ASSERT_FALSE(r);
  EXPECT_NE(r.status().message().find("calibration"), std::string::npos) << r.status().message();
}

TEST(Triangulation, ColumnsOutsideTheDepthRangeAreInvalid) {
  Calibration c = synthetic_calibration();
  c.camera_width = 16;
  c.camera_height = 16;
  ReconstructOptions o;
  o.min_depth_mm = 600;
  o.max_depth_mm = 700;
  auto r = Reconstructor::create(c, o);
  ASSERT_TRUE(r);
  cv::Mat u, truth;
  cast(
      c, [](const cv::Vec3d&) -> std::optional<double> { return 800.0; }, u, truth);
  const cv::Mat xyz = r->triangulate_columns(u);
  for (int i = 0; i < 256; ++i) EXPECT_TRUE(std::isnan(xyz.at<cv::Vec3f>(i / 16, i % 16)[2]));
}

}  // namespace
}  // namespace gvkit::capture
