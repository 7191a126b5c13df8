// Projector gamma: estimated from a rendered calibration sequence, and compensated by a LUT that
// cuts the 3-step phase error more than tenfold.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/calib3d.hpp>

#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/phase_shift.hpp"
#include "gvkit/capture/projector_gamma.hpp"
#include "gvkit/capture/synthetic_renderer.hpp"
#include "gvkit/capture/synthetic_rig.hpp"

namespace gvkit::capture {
namespace {

// A tilted plane 650 mm ahead, filling the camera view.
SyntheticScene plane() {
  SyntheticScene s;
  s.positions_mm = {{-400, -400, 600}, {400, -400, 700}, {400, 400, 700}, {-400, 400, 600}};
  s.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.albedo = {0.8f, 0.8f, 0.8f, 0.8f};
  return s;
}

Calibration small_rig() {
  SyntheticRigOptions o;
  o.camera_width = 64;
  o.camera_height = 48;
  return synthetic_calibration(o);
}

RenderOptions gamma_render(double gamma) {
  RenderOptions r;
  r.projector_gamma = gamma;
  r.bit_depth = 16;
  r.projector_bit_depth = 0;
  return r;
}

TEST(ProjectorGamma, EstimatedFromACalibrationSequence) {
  const Calibration c = small_rig();
  for (double gamma : {1.0, 1.8, 2.2, 2.6}) {
    const SyntheticRenderer renderer(c, gamma_render(gamma));
    const auto frame = renderer.render(
        plane(), gamma_calibration_patterns({c.projector_width, c.projector_height}), 1);
    auto e = estimate_projector_gamma(gamma_calibration_levels(), frame.images);
    ASSERT_TRUE(e) << e.status().message();
    EXPECT_NEAR(e->gamma, gamma, 0.03);
    EXPECT_LT(e->rms_residual, 0.01);
    EXPECT_GT(e->pixels, 1000);
  }
}

TEST(ProjectorGamma, BadCalibrationSequences) {
  std::vector<cv::Mat> dark(17, cv::Mat(20, 20, CV_8U, cv::Scalar(3)));
  auto e = estimate_projector_gamma(gamma_calibration_levels(), dark);
  ASSERT_FALSE(e);
  EXPECT_NE(e.status().message().find("respond"), std::string::npos) << e.status().message();
  EXPECT_FALSE(
      estimate_projector_gamma(gamma_calibration_levels(), {dark.begin(), dark.end() - 1}));
}

// RMS 3-step phase error on the plane (constant offset removed), with the true phase from the
// ground-truth points.
double phase_error_rms(double gamma, double compensation) {
  const Calibration c = small_rig();
  auto patterns = create_pattern_set("psp3-f16").value();
  std::vector<cv::Mat> images = patterns->generate({c.projector_width, c.projector_height});
  if (compensation > 0) compensate_gamma(images, compensation);
  const SyntheticRenderer renderer(c, gamma_render(gamma));
  const auto frame = renderer.render(plane(), images, 1);
  const WrappedPhase w = decode_phase_shift(frame.images, 0, 3, 0.999);
  cv::Vec3d rvec;
  cv::Rodrigues(c.R_proj_from_cam(), rvec);
  const double pitch = patterns->pitch_px(c.projector_width);
  std::vector<double> d;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      if (!frame.truth.lit.at<uint8_t>(y, x)) continue;
      std::vector<cv::Point3d> p{cv::Point3d(cv::Vec3d(frame.truth.xyz_mm.at<cv::Vec3f>(y, x)))};
      std::vector<cv::Point2d> q;
      cv::projectPoints(p, rvec, c.t_proj_from_cam_mm(), c.projector_K, c.projector_dist, q);
      d.push_back(std::remainder(w.phase.at<float>(y, x) - 2 * CV_PI * q[0].x / pitch, 2 * CV_PI));
    }
  double mean = 0, sum2 = 0;
  for (double v : d) mean += v / d.size();
  for (double v : d) sum2 += (v - mean) * (v - mean);
  return std::sqrt(sum2 / d.size());
}

TEST(ProjectorGamma, CompensationCutsThreeStepPhaseErrorTenfold) {
  const double linear = phase_error_rms(1.0, 0);
  const double raw = phase_error_rms(2.2, 0);
  // Estimate, then compensate with the estimate.
  const Calibration c = small_rig();
  const SyntheticRenderer renderer(c, gamma_render(2.2));
  const auto calib = renderer.render(
      plane(), gamma_calibration_patterns({c.projector_width, c.projector_height}), 1);
  auto e = estimate_projector_gamma(gamma_calibration_levels(), calib.images);
  ASSERT_TRUE(e);
  const double compensated = phase_error_rms(2.2, e->gamma);
  EXPECT_GT(raw, 0.1) << "gamma 2.2 bends 3-step fringes";
  EXPECT_LT(linear, 0.01);
  EXPECT_GT(raw / compensated, 10.0) << raw << " rad -> " << compensated << " rad";
  RecordProperty("raw_rad", std::to_string(raw));
  RecordProperty("compensated_rad", std::to_string(compensated));
}

}  // namespace
}  // namespace gvkit::capture
