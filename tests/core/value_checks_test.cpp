#include <cmath>

#include <gtest/gtest.h>

#include "gvkit/core/calibration.hpp"
#include "gvkit/core/fringe_set.hpp"
#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/range_scan.hpp"

namespace gvkit {
namespace {

Calibration simple_rig() {
  Calibration c;
  c.camera_K = {500, 0, 256, 0, 500, 256, 0, 0, 1};
  c.camera_width = c.camera_height = 512;
  c.projector_K = {900, 0, 456, 0, 900, 285, 0, 0, 1};
  c.projector_width = 912;
  c.projector_height = 570;
  c.t_cam_from_proj_mm = {200, 0, 0};
  return c;
}

TEST(CalibrationCheck, AcceptsAValidRig) { EXPECT_TRUE(simple_rig().check().is_ok()); }

TEST(CalibrationCheck, RejectsBadFieldsByName) {
  Calibration c = simple_rig();
  c.camera_K(0, 0) = NAN;
  EXPECT_NE(c.check().message().find("camera matrix has non-finite"), std::string::npos);
  c = simple_rig();
  c.projector_K(1, 1) = -3;
  EXPECT_NE(c.check().message().find("projector focal"), std::string::npos);
  c = simple_rig();
  c.t_cam_from_proj_mm = {0, 0, 0};
  EXPECT_EQ(c.check().code(), StatusCode::kFailedPrecondition);
  c = simple_rig();
  c.R_cam_from_proj(0, 1) = 0.5;
  EXPECT_NE(c.check().message().find("not a rotation"), std::string::npos);
  c = simple_rig();
  c.camera_dist = {0.1, 0.2, 0.3};
  EXPECT_NE(c.check().message().find("distortion"), std::string::npos);
}

TEST(CalibrationCheck, InverseTransformRoundTrips) {
  Calibration c = simple_rig();
  const double a = CV_PI / 12;
  c.R_cam_from_proj = {std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a)};
  const cv::Vec3d p_proj(10, -20, 600);
  const cv::Vec3d p_cam = c.R_cam_from_proj * p_proj + c.t_cam_from_proj_mm;
  const cv::Vec3d back = c.R_proj_from_cam() * p_cam + c.t_proj_from_cam_mm();
  EXPECT_LT(cv::norm(back - p_proj), 1e-9);
}

TEST(FringeSetCheck, NamesTheOffendingImage) {
  FringeSet set;
  EXPECT_FALSE(set.check().is_ok());
  set.images = {cv::Mat(4, 4, CV_8U), cv::Mat(4, 4, CV_8U), cv::Mat(5, 4, CV_8U)};
  EXPECT_EQ(set.check().message(), "image 2: size 4x5, expected 4x4");
  set.images[2] = cv::Mat(4, 4, CV_32F);
  EXPECT_EQ(set.check().code(), StatusCode::kUnsupported);
  set.images[2] = cv::Mat(4, 4, CV_16U);
  EXPECT_TRUE(set.check().is_ok());
}

TEST(RangeScanCheck, ValidPixelsMustBeFinite) {
  RangeScan scan;
  scan.xyz_mm = cv::Mat(2, 2, CV_32FC3, cv::Scalar(1, 2, 3));
  scan.valid = cv::Mat(2, 2, CV_8U, cv::Scalar(255));
  EXPECT_TRUE(scan.check().is_ok());
  EXPECT_DOUBLE_EQ(scan.valid_fraction(), 1.0);
  scan.xyz_mm.at<cv::Vec3f>(1, 1) = cv::Vec3f(NAN, NAN, NAN);
  EXPECT_FALSE(scan.check().is_ok());
  scan.valid.at<uint8_t>(1, 1) = 0;
  EXPECT_TRUE(scan.check().is_ok());
  EXPECT_DOUBLE_EQ(scan.valid_fraction(), 0.75);
}

TEST(GeometryImageCheck, MaskSizeMustMatch) {
  GeometryImage gi;
  gi.xyz_mm = cv::Mat(3, 3, CV_32FC3, cv::Scalar(0, 0, 0));
  gi.domain_mask = cv::Mat(3, 4, CV_8U, cv::Scalar(255));
  EXPECT_FALSE(gi.check().is_ok());
  gi.domain_mask = cv::Mat(3, 3, CV_8U, cv::Scalar(255));
  EXPECT_TRUE(gi.check().is_ok());
}

}  // namespace
}  // namespace gvkit
