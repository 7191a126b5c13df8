// One test per pattern family a user may bring, each the way such a user arrives: the camera
// images as a plain numbered folder (BMP or PNG, 8 or 16 bit), the calibration in another tool's
// layout (procam, SLStudio, OpenCV stereo_calib split in two files, one file per device), the
// pattern set named or described in JSON. Everything goes through the readers a user's data
// goes through, and the depth must match the renderer's truth.
#include <gtest/gtest.h>

#include <fstream>

#include <opencv2/core/persistence.hpp>

#include "gvkit/capture/fringe_folder.hpp"
#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/reconstructor.hpp"
#include "gvkit/core/calibration_io.hpp"
#include "plain_folder_fixture.hpp"
#include "support/test_support.hpp"

namespace gvkit::capture {
namespace {
using testing::TempDir;
namespace fs = std::filesystem;

struct Case {
  std::string pattern;  // a name, or a JSON spec written to spec.json
  cv::Size camera, projector;
  std::string ext;  // bmp (8 bit) or png (12 bit in 16)
  CalibrationFormat layout;
  double max_rms_mm, min_valid_share;
  double depth_prior_mm = 650;  // spatially unwrapped sets: the scene's typical depth
};

class FamilyFolder : public ::testing::Test {
 protected:
  // Renders the bump through the case's patterns, writes the folder and the calibration, then
  // reads them back as a user's data and reconstructs.
  fixture::DepthError run(const Case& c, const Calibration& rig, const Calibration& written,
                          RenderOptions render = {}) {
    const fs::path folder = dir_ / "images";
    auto patterns = create_pattern_set(c.pattern);
    EXPECT_TRUE(patterns) << patterns.status().message();
    if (!patterns) return {};
    render.bit_depth = c.ext == "png" ? 12 : 8;
    render.noise_sigma = 0.003;
    const SyntheticScene scene = fixture::bump_scene();
    const SyntheticRenderer renderer(rig, render);
    const SyntheticFrame frame = renderer.render(
        scene, (*patterns)->generate({rig.projector_width, rig.projector_height}), 7);
    fixture::write_numbered(folder, frame.images, "capture", c.ext);
    const std::vector<fs::path> calibration_files = write_layout(written, c.layout);

    // The user's side.
    auto user_patterns = create_pattern_set(c.pattern);
    EXPECT_TRUE(user_patterns);
    auto listed = list_fringe_folder(folder, (*user_patterns)->image_count());
    EXPECT_TRUE(listed) << listed.status().message();
    if (!listed) return {};
    auto fringes = read_fringe_frame(*listed, 0);
    EXPECT_TRUE(fringes) << fringes.status().message();
    CalibrationReadOptions read_options;
    read_options.camera_size = fringes->size();
    read_options.projector_size = {rig.projector_width, rig.projector_height};
    auto loaded = read_calibration(calibration_files, read_options);
    EXPECT_TRUE(loaded) << loaded.status().message();
    EXPECT_EQ(loaded->format, c.layout);
    Calibration calibration = loaded->calibration;
    if (calibration.camera_width != fringes->size().width) {
      auto scaled = rescale_camera(calibration, fringes->size());
      EXPECT_TRUE(scaled) << scaled.status().message();
      calibration = *scaled;
    }
    ReconstructOptions options;
    options.depth_prior_mm = c.depth_prior_mm;
    auto scan = reconstruct(*fringes, **user_patterns, calibration, options);
    EXPECT_TRUE(scan) << scan.status().message();
    if (!scan) return {};
    const fixture::DepthError e = fixture::depth_error(*scan, frame.truth);
    EXPECT_LT(e.rms_mm, c.max_rms_mm) << c.pattern;
    EXPECT_GT(e.valid_share, c.min_valid_share) << c.pattern;
    EXPECT_GT(e.compared, c.camera.area() / 3) << c.pattern;
    std::printf("%s (%s, %s): RMS %.3f mm, max %.2f mm, valid %.4f of %d lit px\n",
                c.pattern.c_str(), c.ext.c_str(), calibration_format_name(c.layout), e.rms_mm,
                e.max_mm, e.valid_share, e.compared);
    return e;
  }

  // The calibration as the tool behind each layout writes it (cv::FileStorage, its keys).
  std::vector<fs::path> write_layout(const Calibration& c, CalibrationFormat layout) {
    const cv::Mat R(c.R_proj_from_cam()), T(c.t_proj_from_cam_mm());
    const cv::Mat zeros = cv::Mat::zeros(1, 5, CV_64F);
    switch (layout) {
      case CalibrationFormat::kStereo: {
        const fs::path intrinsics = dir_ / "intrinsics.xml", extrinsics = dir_ / "extrinsics.xml";
        cv::FileStorage a(intrinsics.string(), cv::FileStorage::WRITE);
        a << "M1" << cv::Mat(c.camera_K) << "D1" << zeros << "M2" << cv::Mat(c.projector_K) << "D2"
          << zeros;
        cv::FileStorage b(extrinsics.string(), cv::FileStorage::WRITE);
        b << "R" << R << "T" << T;
        return {intrinsics, extrinsics};
      }
      case CalibrationFormat::kCameraFiles: {
        std::vector<fs::path> files = {dir_ / "camera.yml", dir_ / "projector.yml",
                                       dir_ / "stereo.yml"};
        cv::FileStorage cam(files[0].string(), cv::FileStorage::WRITE);
        cam << "image_width" << c.camera_width << "image_height" << c.camera_height
            << "camera_matrix" << cv::Mat(c.camera_K) << "distortion_coefficients" << zeros;
        cv::FileStorage proj(files[1].string(), cv::FileStorage::WRITE);
        proj << "image_width" << c.projector_width << "image_height" << c.projector_height
             << "camera_matrix" << cv::Mat(c.projector_K) << "distortion_coefficients" << zeros;
        cv::FileStorage ext(files[2].string(), cv::FileStorage::WRITE);
        ext << "R" << R << "T" << T;
        return files;
      }
      default: {
        const fs::path path = dir_ / "calibration.yml";
        EXPECT_TRUE(write_calibration(path, c, layout).is_ok());
        return {path};
      }
    }
  }

  TempDir dir_;
};

TEST_F(FamilyFolder, ComplementaryGrayWithFreePitchReferencesAndGrayFirst) {
  const Case c{"cgray5-psp4-p40-owbgp",    {160, 128}, {912, 570}, "bmp",
               CalibrationFormat::kProcam, 0.25,       0.97};
  const Calibration rig = fixture::rig(c.camera, c.projector);
  run(c, rig, rig);
}

TEST_F(FamilyFolder, HeterodyneThreeFrequencies) {
  const Case c{"het4-f70-f64-f59",         {160, 128}, {912, 570}, "png",
               CalibrationFormat::kStereo, 0.15,       0.97};
  const Calibration rig = fixture::rig(c.camera, c.projector);
  run(c, rig, rig);
}

TEST_F(FamilyFolder, SixStepWithPositiveShiftsAndSpatialUnwrapping) {
  // Most of the view is the wall 800 mm away: the depth prior says so (--depth-prior).
  const Case c{"psp6-f16-pos", {160, 128}, {912, 570}, "png", CalibrationFormat::kSlStudio,
               0.25,           0.95,       780};
  const Calibration rig = fixture::rig(c.camera, c.projector);
  run(c, rig, rig);
}

TEST_F(FamilyFolder, JsonSpecWithInversesAfterAndSineFringes) {
  std::ofstream(dir_ / "spec.json") << R"({
    "family": "gray-code", "gray_bits": 4, "complementary": true, "inverses": "after",
    "steps": 3, "periods": [16], "order": ["phase", "gray", "black", "white"],
    "shift_sign": 1, "phase_offset_deg": 90})";
  const Case c{(dir_ / "spec.json").string(),   {160, 128}, {912, 570}, "bmp",
               CalibrationFormat::kCameraFiles, 0.45,       0.97};
  const Calibration rig = fixture::rig(c.camera, c.projector);
  run(c, rig, rig);
}

// A 1280x1024 camera and a 1280x800 projector, calibrated at full resolution; the images are the
// camera's 4x4-binned 320x256 frames (rendered at that size), the calibration rescaled to them.
TEST_F(FamilyFolder, MegapixelRigBinnedFourTimes) {
  const Case c{"cgray5-psp4", {320, 256}, {1280, 800}, "png", CalibrationFormat::kSlStudio,
               0.15,          0.97};
  const Calibration binned = fixture::rig(c.camera, c.projector);
  const Calibration full = fixture::rig({1280, 1024}, c.projector);
  run(c, binned, full);
}

}  // namespace
}  // namespace gvkit::capture
