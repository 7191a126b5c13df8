#include "gvkit/core/calibration_io.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include <opencv2/core/persistence.hpp>

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

// The rig's proj_from_cam transform, as stereoCalibrate(camera, projector) reports it.
cv::Mat R_proj_from_cam(const Calibration& c) { return cv::Mat(c.R_proj_from_cam()); }
cv::Mat t_proj_from_cam(const Calibration& c) { return cv::Mat(c.t_proj_from_cam_mm()); }

void expect_same_rig(const Calibration& got, const Calibration& want, double t_scale = 1) {
  EXPECT_LT(cv::norm(got.camera_K - want.camera_K), 1e-9);
  EXPECT_LT(cv::norm(got.projector_K - want.projector_K), 1e-9);
  EXPECT_LT(cv::norm(got.R_cam_from_proj - want.R_cam_from_proj), 1e-9);
  EXPECT_LT(cv::norm(got.t_cam_from_proj_mm - t_scale * want.t_cam_from_proj_mm), 1e-6);
  EXPECT_EQ(got.camera_dist, want.camera_dist);
  EXPECT_TRUE(got.projector_dist.empty());  // written as five zeros
  EXPECT_EQ(got.camera_width, want.camera_width);
  EXPECT_EQ(got.camera_height, want.camera_height);
  EXPECT_EQ(got.projector_width, want.projector_width);
  EXPECT_EQ(got.projector_height, want.projector_height);
}

// Each foreign layout written by cv::FileStorage the way the tool that defines it writes it, in
// YAML and in XML.
class ForeignLayout : public ::testing::TestWithParam<const char*> {
 protected:
  std::string ext() const { return GetParam(); }
  CalibrationReadOptions sizes() const {
    CalibrationReadOptions o;
    o.camera_size = {512, 512};
    o.projector_size = {912, 570};
    return o;
  }
  TempDir dir_;
  const Calibration rig_ = sample_rig();
  const cv::Mat zeros_ = cv::Mat::zeros(5, 1, CV_64F);
};

TEST_P(ForeignLayout, Procam) {
  const auto path = dir_ / ("calibration" + ext());
  {
    cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
    fs << "cam_K" << cv::Mat(rig_.camera_K) << "cam_kc" << cv::Mat(rig_.camera_dist, true)
       << "proj_K" << cv::Mat(rig_.projector_K) << "proj_kc" << zeros_ << "R"
       << R_proj_from_cam(rig_) << "T" << t_proj_from_cam(rig_) << "cam_error" << 0.2
       << "proj_error" << 0.3 << "stereo_error" << 0.25;
  }
  auto loaded = read_calibration(path, sizes());
  ASSERT_TRUE(loaded) << loaded.status().message();
  EXPECT_EQ(loaded->format, CalibrationFormat::kProcam);
  EXPECT_FALSE(loaded->camera_size_from_file);
  EXPECT_FALSE(loaded->projector_size_from_file);
  expect_same_rig(loaded->calibration, rig_);
  EXPECT_DOUBLE_EQ(loaded->calibration.stereo_error_px, 0.25);
  // Without sizes the message names the option that gives them.
  CalibrationReadOptions camera_only;
  camera_only.camera_size = {512, 512};
  auto no_projector = read_calibration(path, camera_only);
  ASSERT_FALSE(no_projector);
  EXPECT_TRUE(testing::contains(no_projector.status().message(), "--projector-size"))
      << no_projector.status().message();
  auto no_camera = read_calibration(path);
  ASSERT_FALSE(no_camera);
  EXPECT_TRUE(testing::contains(no_camera.status().message(), "no camera image size"));
}

TEST_P(ForeignLayout, ProcamVariantsInOtherCaseWithMetresAndRotationVector) {
  const auto path = dir_ / ("variant" + ext());
  cv::Mat rvec(3, 1, CV_64F);
  {
    // A rotation vector for R (axis * angle) and the translation in metres.
    const cv::Matx33d R = rig_.R_proj_from_cam();
    const double angle = std::acos((R(0, 0) + R(1, 1) + R(2, 2) - 1) / 2);
    const cv::Vec3d axis =
        cv::normalize(cv::Vec3d(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1)));
    for (int i = 0; i < 3; ++i) rvec.at<double>(i) = axis[i] * angle;
    cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
    fs << "Cam_K" << cv::Mat(rig_.camera_K) << "Cam_dist" << cv::Mat(rig_.camera_dist, true)
       << "Proj_K" << cv::Mat(rig_.projector_K) << "Proj_Kc" << zeros_ << "R" << rvec << "T"
       << cv::Mat(t_proj_from_cam(rig_) / 1000.0);
  }
  CalibrationReadOptions o = sizes();
  o.length_unit_mm = 1000;
  auto loaded = read_calibration(path, o);
  ASSERT_TRUE(loaded) << loaded.status().message();
  EXPECT_EQ(loaded->format, CalibrationFormat::kProcam);
  expect_same_rig(loaded->calibration, rig_);
}

TEST_P(ForeignLayout, SlStudio) {
  const auto path = dir_ / ("calibration" + ext());
  {
    cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
    cv::Mat Kc, kc;
    cv::Mat(rig_.camera_K).convertTo(Kc, CV_32F);  // SLStudio writes floats
    fs << "Kc" << Kc << "kc" << cv::Mat(rig_.camera_dist, true) << "Kp" << cv::Mat(rig_.projector_K)
       << "kp" << zeros_ << "Rp" << R_proj_from_cam(rig_) << "Tp" << t_proj_from_cam(rig_)
       << "frameWidth" << 512 << "frameHeight" << 512 << "screenResX" << 912 << "screenResY" << 570;
  }
  auto loaded = read_calibration(path);
  ASSERT_TRUE(loaded) << loaded.status().message();
  EXPECT_EQ(loaded->format, CalibrationFormat::kSlStudio);
  EXPECT_TRUE(loaded->camera_size_from_file);
  EXPECT_LT(cv::norm(loaded->calibration.camera_K - rig_.camera_K), 1e-3);
  EXPECT_LT(cv::norm(loaded->calibration.t_cam_from_proj_mm - rig_.t_cam_from_proj_mm), 1e-6);
  // A projector size that contradicts the file is refused.
  CalibrationReadOptions other;
  other.projector_size = {1024, 768};
  auto contradiction = read_calibration(path, other);
  ASSERT_FALSE(contradiction);
  EXPECT_TRUE(testing::contains(contradiction.status().message(), "912x570 projector"))
      << contradiction.status().message();
}

TEST_P(ForeignLayout, OpenCvStereoCalibSplitIntoIntrinsicsAndExtrinsics) {
  const auto intrinsics = dir_ / ("intrinsics" + ext());
  const auto extrinsics = dir_ / ("extrinsics" + ext());
  {
    cv::FileStorage fs(intrinsics.string(), cv::FileStorage::WRITE);
    fs << "M1" << cv::Mat(rig_.camera_K) << "D1" << cv::Mat(rig_.camera_dist, true).t() << "M2"
       << cv::Mat(rig_.projector_K) << "D2" << zeros_.t();
  }
  {
    cv::FileStorage fs(extrinsics.string(), cv::FileStorage::WRITE);
    fs << "R" << R_proj_from_cam(rig_) << "T" << t_proj_from_cam(rig_) << "imageSize"
       << cv::Size(512, 512);
  }
  auto only_intrinsics = read_calibration(intrinsics, sizes());
  ASSERT_FALSE(only_intrinsics);
  EXPECT_TRUE(testing::contains(only_intrinsics.status().message(), "missing field R, T"))
      << only_intrinsics.status().message();
  CalibrationReadOptions projector_only;
  projector_only.projector_size = {912, 570};
  auto loaded =
      read_calibration(std::vector<std::filesystem::path>{intrinsics, extrinsics}, projector_only);
  ASSERT_TRUE(loaded) << loaded.status().message();
  EXPECT_EQ(loaded->format, CalibrationFormat::kStereo);
  EXPECT_TRUE(loaded->camera_size_from_file);  // imageSize
  expect_same_rig(loaded->calibration, rig_);
}

TEST_P(ForeignLayout, OneFilePerDeviceFromTheOpenCvSample) {
  const auto camera = dir_ / ("camera" + ext());
  const auto projector = dir_ / ("projector" + ext());
  const auto extrinsics = dir_ / ("extrinsics" + ext());
  {
    cv::FileStorage fs(camera.string(), cv::FileStorage::WRITE);
    fs << "image_width" << 512 << "image_height" << 512 << "camera_matrix" << cv::Mat(rig_.camera_K)
       << "distortion_coefficients" << cv::Mat(rig_.camera_dist, true) << "avg_reprojection_error"
       << 0.2;
  }
  {
    cv::FileStorage fs(projector.string(), cv::FileStorage::WRITE);
    fs << "image_width" << 912 << "image_height" << 570 << "camera_matrix"
       << cv::Mat(rig_.projector_K) << "distortion_coefficients" << zeros_;
  }
  {
    cv::FileStorage fs(extrinsics.string(), cv::FileStorage::WRITE);
    fs << "R" << R_proj_from_cam(rig_) << "T" << t_proj_from_cam(rig_);
  }
  auto loaded = read_calibration(std::vector<std::filesystem::path>{camera, projector, extrinsics});
  ASSERT_TRUE(loaded) << loaded.status().message();
  EXPECT_EQ(loaded->format, CalibrationFormat::kCameraFiles);
  expect_same_rig(loaded->calibration, rig_);
}

TEST_P(ForeignLayout, UnknownLayoutListsTheKeysFound) {
  const auto path = dir_ / ("odd" + ext());
  {
    cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
    fs << "intrinsic" << cv::Mat(rig_.camera_K) << "baseline" << 200.0;
  }
  auto r = read_calibration(path, sizes());
  ASSERT_FALSE(r);
  const std::string m = r.status().message();
  EXPECT_TRUE(testing::contains(m, path.string() + ": unknown calibration layout")) << m;
  EXPECT_TRUE(testing::contains(m, "keys found: intrinsic, baseline")) << m;
  for (const char* layout : {"gvkit (camera_K", "SLStudio (Kc", "procam / scan3d-capture (cam_K",
                             "OpenCV stereo_calib (M1", "camera_matrix"})
    EXPECT_TRUE(testing::contains(m, layout)) << layout << "\n" << m;
  // A layout with most of its keys names what is missing.
  const auto partial = dir_ / ("partial" + ext());
  {
    cv::FileStorage fs(partial.string(), cv::FileStorage::WRITE);
    fs << "cam_K" << cv::Mat(rig_.camera_K) << "proj_K" << cv::Mat(rig_.projector_K) << "R"
       << R_proj_from_cam(rig_);
  }
  auto p = read_calibration(partial, sizes());
  ASSERT_FALSE(p);
  EXPECT_TRUE(testing::contains(p.status().message(), "missing field T of the procam"))
      << p.status().message();
}

INSTANTIATE_TEST_SUITE_P(YamlAndXml, ForeignLayout, ::testing::Values(".yml", ".xml"));

TEST(CalibrationIo, ForeignLayoutsWrittenByGvkitReadBack) {
  TempDir dir;
  const Calibration rig = sample_rig();
  for (auto format :
       {CalibrationFormat::kSlStudio, CalibrationFormat::kProcam, CalibrationFormat::kStereo}) {
    const auto path = dir / (std::string(calibration_format_name(format)) + ".yaml");
    ASSERT_TRUE(write_calibration(path, rig, format).is_ok());
    CalibrationReadOptions o;
    o.camera_size = {512, 512};
    o.projector_size = {912, 570};
    auto back = read_calibration(path, o);
    ASSERT_TRUE(back) << back.status().message();
    EXPECT_EQ(back->format, format);
    expect_same_rig(back->calibration, rig);
  }
}

TEST(CalibrationIo, RescaledCameraKeepsPixelCentres) {
  const Calibration rig = sample_rig();
  auto half = rescale_camera(rig, {256, 256});
  ASSERT_TRUE(half) << half.status().message();
  EXPECT_DOUBLE_EQ(half->camera_K(0, 0), 550);
  EXPECT_DOUBLE_EQ(half->camera_K(0, 2), (256.5 + 0.5) * 0.5 - 0.5);
  EXPECT_EQ(half->camera_width, 256);
  EXPECT_EQ(half->projector_K, rig.projector_K);
  EXPECT_FALSE(rescale_camera(rig, {256, 200}));
}

}  // namespace
}  // namespace gvkit
