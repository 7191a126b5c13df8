#include "gvkit/core/calibration_io.hpp"

#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::TempDir;

Calibration sample_rig() {
  Calibration c;
  c.camera_K = {1100, 0, 256.5, 0, 1101, 255.5, 0, 0, 1};
  c.camera_dist = {-0.05, 0.01, 0.001, -0.002, 0.0};
  c.camera_width = c.camera_height = 512;
  c.projector_K = {1500, 0, 456, 0, 1500, 570, 0, 0, 1};
  c.projector_width = 912;
  c.projector_height = 570;
  const double a = 17.0 * CV_PI / 180;
  c.R_cam_from_proj = {std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a)};
  c.t_cam_from_proj_mm = {200, 0, 20};
  c.fringe_pitch_px = 57;
  return c;
}

TEST(CalibrationIo, GvkitFormatRoundTripsInEveryExtension) {
  TempDir dir;
  const Calibration c = sample_rig();
  for (const char* name : {"c.yaml", "c.json", "c.xml"}) {
    ASSERT_TRUE(write_calibration(dir / name, c).is_ok()) << name;
    auto back = read_calibration(dir / name);
    ASSERT_TRUE(back.is_ok()) << back.status().message();
    EXPECT_EQ(back->format, CalibrationFormat::kGvkit);
    const Calibration& b = back->calibration;
    EXPECT_LT(cv::norm(b.camera_K - c.camera_K), 1e-9);
    EXPECT_LT(cv::norm(b.projector_K - c.projector_K), 1e-9);
    EXPECT_LT(cv::norm(b.R_cam_from_proj - c.R_cam_from_proj), 1e-12);
    EXPECT_LT(cv::norm(b.t_cam_from_proj_mm - c.t_cam_from_proj_mm), 1e-12);
    EXPECT_EQ(b.camera_dist, c.camera_dist);
    EXPECT_EQ(b.projector_width, 912);
    EXPECT_DOUBLE_EQ(b.fringe_pitch_px, 57);
  }
}

TEST(CalibrationIo, ReadsSlStudioCalibration) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto loaded = read_calibration(data / "slstudio-skull-2x3" / "calibration.xml");
  ASSERT_TRUE(loaded.is_ok()) << loaded.status().message();
  EXPECT_EQ(loaded->format, CalibrationFormat::kSlStudio);
  const Calibration& c = loaded->calibration;
  EXPECT_NEAR(c.camera_K(0, 0), 2195.12036, 1e-3);
  EXPECT_NEAR(c.projector_K(1, 2), 1109.11121, 1e-3);
  EXPECT_EQ(c.camera_width, 1688);
  EXPECT_EQ(c.projector_height, 1140);
  ASSERT_EQ(c.camera_dist.size(), 5u);
  EXPECT_NEAR(c.camera_dist[0], -0.0580352657, 1e-9);
  // Rp, Tp are proj_from_cam: the projector centre in camera coordinates is -Rp^T Tp.
  const cv::Vec3d Tp(-145.282562, -36.4983406, 67.9231644);
  EXPECT_NEAR(c.baseline_mm(), cv::norm(Tp), 1e-3);
  const cv::Vec3d back = c.R_proj_from_cam() * c.t_cam_from_proj_mm + c.t_proj_from_cam_mm();
  EXPECT_LT(cv::norm(back), 1e-9);  // the projector centre maps to the projector origin
  EXPECT_NEAR(c.stereo_error_px, 0.42199749739974501, 1e-12);
}

TEST(CalibrationIo, MissingAndNonFiniteFieldsAreNamed) {
  TempDir dir;
  ASSERT_TRUE(write_calibration(dir / "good.yaml", sample_rig()).is_ok());
  std::string text = *read_file(dir / "good.yaml");
  std::string no_proj = text;
  no_proj.replace(no_proj.find("projector_K"), 11, "projector_Q");
  ASSERT_TRUE(write_file_atomically(dir / "missing.yaml", no_proj).is_ok());
  auto missing = read_calibration(dir / "missing.yaml");
  ASSERT_FALSE(missing.is_ok());
  EXPECT_NE(missing.status().message().find("missing.yaml"), std::string::npos);
  EXPECT_NE(missing.status().message().find("projector_K"), std::string::npos);

  std::string nan_text = text;
  const size_t at = nan_text.find("1100.");
  ASSERT_NE(at, std::string::npos);
  nan_text.replace(at, 5, ".Nan ");
  ASSERT_TRUE(write_file_atomically(dir / "nan.yaml", nan_text).is_ok());
  auto nan = read_calibration(dir / "nan.yaml");
  ASSERT_FALSE(nan.is_ok());
  EXPECT_NE(nan.status().message().find("non-finite"), std::string::npos);

  ASSERT_TRUE(write_file_atomically(dir / "junk.yaml", "%YAML:1.0\n[[[").is_ok());
  EXPECT_FALSE(read_calibration(dir / "junk.yaml").is_ok());
  EXPECT_EQ(read_calibration(dir / "none.yaml").status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace gvkit
