// Projector-camera calibration on synthetic checkerboard captures with a known calibration.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/calib3d.hpp>

#include "gvkit/capture/projector_calibration.hpp"
#include "gvkit/capture/synthetic_board.hpp"
#include "gvkit/capture/synthetic_rig.hpp"

namespace gvkit::capture {
namespace {

TEST(ProjectorCalibration, RecoversAKnownRig) {
  SyntheticRigOptions rig;
  rig.camera_width = 400;
  rig.camera_height = 300;
  rig.camera_dist = {-0.06, 0.03, 0, 0, 0};
  const Calibration truth = synthetic_calibration(rig);
  CalibrationBoard board;
  ProjectorCalibrationOptions options;
  options.pattern = "mf3-f16-f1";
  RenderOptions render;
  render.bit_depth = 12;
  auto captures = render_calibration_captures(truth, board, options, render, 8, 1);
  ASSERT_TRUE(captures) << captures.status().message();
  auto result = calibrate_projector_camera(*captures, board, options);
  ASSERT_TRUE(result) << result.status().message();
  for (const auto& s : result->skipped) ADD_FAILURE() << s;
  const Calibration& c = result->calibration;
  EXPECT_EQ(result->poses_used, 8);
  auto relative = [](double a, double b) { return std::abs(a - b) / b; };
  EXPECT_LT(relative(c.camera_K(0, 0), truth.camera_K(0, 0)), 0.005);
  EXPECT_LT(relative(c.camera_K(1, 1), truth.camera_K(1, 1)), 0.005);
  EXPECT_LT(relative(c.projector_K(0, 0), truth.projector_K(0, 0)), 0.005);
  EXPECT_LT(relative(c.projector_K(1, 1), truth.projector_K(1, 1)), 0.005);
  EXPECT_LT(relative(c.baseline_mm(), truth.baseline_mm()), 0.01);
  // Distortion coefficients trade off against each other; their effect must match: the
  // undistorted position of pixels across the image agrees within half a pixel.
  std::vector<cv::Point2f> grid, a, b;
  // (Over the middle of the image, where the boards were; the corners are extrapolation.)
  for (int y = 50; y <= 250; y += 25)
    for (int x = 75; x <= 325; x += 25)
      grid.emplace_back(static_cast<float>(x), static_cast<float>(y));
  cv::undistortPoints(grid, a, c.camera_K, c.camera_dist, cv::noArray(), truth.camera_K);
  cv::undistortPoints(grid, b, truth.camera_K, truth.camera_dist, cv::noArray(), truth.camera_K);
  // The principal point is weakly constrained by few poses (a shift trades against the pose):
  // compare after removing the mean shift.
  cv::Point2f shift(0, 0);
  for (size_t i = 0; i < grid.size(); ++i) shift += (a[i] - b[i]) * (1.0f / grid.size());
  EXPECT_LT(cv::norm(shift), 15.0);
  for (size_t i = 0; i < grid.size(); ++i) EXPECT_LT(cv::norm(a[i] - b[i] - shift), 1.0) << grid[i];
  // Rendering has no anti-aliasing, so corners carry ~0.3 px of error.
  EXPECT_LT(c.camera_error_px, 0.8);
  EXPECT_LT(c.projector_error_px, 0.8);
  EXPECT_LT(c.stereo_error_px, 0.8);
  EXPECT_TRUE(c.check()) << c.check().message();
  std::printf(
      "camera f %.2f (true %.2f), projector f %.2f (true %.2f), baseline %.2f mm, "
      "errors %.3f / %.3f / %.3f px\n",
      c.camera_K(0, 0), truth.camera_K(0, 0), c.projector_K(0, 0), truth.projector_K(0, 0),
      c.baseline_mm(), c.camera_error_px, c.projector_error_px, c.stereo_error_px);
}

TEST(ProjectorCalibration, BadCaptures) {
  CalibrationBoard board;
  ProjectorCalibrationOptions options;
  options.pattern = "mf3-f16-f1";
  FringeSet wrong;
  wrong.images.assign(3, cv::Mat(50, 50, CV_8U, cv::Scalar(0)));
  auto r = calibrate_projector_camera({wrong}, board, options);
  ASSERT_FALSE(r);
  EXPECT_NE(r.status().message().find("capture 0"), std::string::npos) << r.status().message();
  FringeSet dark;
  dark.images.assign(13, cv::Mat(50, 50, CV_8U, cv::Scalar(0)));
  auto d = calibrate_projector_camera({dark, dark, dark}, board, options);
  ASSERT_FALSE(d);
  EXPECT_NE(d.status().message().find("need 3"), std::string::npos) << d.status().message();
  board.inner_corners_x = 1;
  EXPECT_FALSE(calibrate_projector_camera({dark}, board, options));
}

}  // namespace
}  // namespace gvkit::capture
