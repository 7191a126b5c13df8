// Two cameras and a projector that only labels the surface: each camera decodes the absolute
// projector column, the pair is rectified and matched along rows, and the points (left camera
// frame, left pixel grid) must match the renderer's truth. The right camera is toed in and has
// lens distortion (rectified by gvkit), or the pair is already rectified; the calibration is
// written the way OpenCV's stereo_calib sample writes it.
#include <gtest/gtest.h>

#include <cstdio>

#include <opencv2/core/persistence.hpp>

#include "gvkit/capture/ground_truth.hpp"
#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/stereo_reconstructor.hpp"
#include "gvkit/core/json_io.hpp"
#include "plain_folder_fixture.hpp"
#include "support/test_support.hpp"

namespace gvkit::capture {
namespace {

struct Pair {
  Calibration left, right;  // each camera with the projector (for rendering)
  cv::Matx33d R_right_from_left;
  cv::Vec3d t_right_from_left_mm;
};

// The right camera `offset_mm` to the left camera's right, turned `toe_deg` about y towards the
// scene, with the given lens distortion.
Pair make_pair(double offset_mm, double toe_deg, std::vector<double> right_dist) {
  Pair p;
  p.left = fixture::rig({160, 128});
  const double a = toe_deg * CV_PI / 180;
  // Camera axes of the right camera in left coordinates: z turned towards -x.
  const cv::Matx33d R_left_from_right(std::cos(a), 0, -std::sin(a), 0, 1, 0, std::sin(a), 0,
                                      std::cos(a));
  p.R_right_from_left = R_left_from_right.t();
  p.t_right_from_left_mm = -(p.R_right_from_left * cv::Vec3d(offset_mm, 0, 0));
  p.right = p.left;
  p.right.camera_dist = right_dist;
  p.right.R_cam_from_proj = p.R_right_from_left * p.left.R_cam_from_proj;
  p.right.t_cam_from_proj_mm =
      p.R_right_from_left * p.left.t_cam_from_proj_mm + p.t_right_from_left_mm;
  return p;
}

SyntheticScene in_frame(SyntheticScene scene, const cv::Matx33d& R, const cv::Vec3d& t) {
  for (auto& x : scene.positions_mm) x = R * x + t;
  return scene;
}

// Renders the pair into dir (left/capture_1.bmp ..., right/..., intrinsics.yml + extrinsics.yml
// as stereo_calib writes them, gt/frame_000000.exr for the left camera), reads the calibration
// back, reconstructs and compares with the left camera's truth.
fixture::DepthError run(const Pair& pair, const std::string& pattern, const testing::TempDir& dir) {
  auto set = create_pattern_set(pattern);
  EXPECT_TRUE(set);
  const std::vector<cv::Mat> patterns = (*set)->generate({912, 570});
  const SyntheticScene scene = fixture::bump_scene();
  RenderOptions render;
  render.noise_sigma = 0.003;
  const SyntheticFrame left = SyntheticRenderer(pair.left, render).render(scene, patterns, 1);
  const SyntheticFrame right =
      SyntheticRenderer(pair.right, render)
          .render(in_frame(scene, pair.R_right_from_left, pair.t_right_from_left_mm), patterns, 2);

  fixture::write_numbered(dir / "left", left.images, "capture_", "bmp");
  fixture::write_numbered(dir / "right", right.images, "capture_", "bmp");
  std::filesystem::create_directories(dir / "gt");
  EXPECT_TRUE(
      write_ground_truth_exr(dir / "gt" / "frame_000000.exr", ground_truth_of(left.truth, scene))
          .is_ok());
  const auto intrinsics = dir / "intrinsics.yml", extrinsics = dir / "extrinsics.yml";
  {
    cv::FileStorage fs(intrinsics.string(), cv::FileStorage::WRITE);
    fs << "M1" << cv::Mat(pair.left.camera_K) << "D1" << cv::Mat::zeros(1, 5, CV_64F) << "M2"
       << cv::Mat(pair.right.camera_K) << "D2"
       << (pair.right.camera_dist.empty() ? cv::Mat(cv::Mat::zeros(1, 5, CV_64F))
                                          : cv::Mat(pair.right.camera_dist, true).t());
    cv::FileStorage ex(extrinsics.string(), cv::FileStorage::WRITE);
    ex << "R" << cv::Mat(pair.R_right_from_left) << "T" << cv::Mat(pair.t_right_from_left_mm);
  }
  auto devices = read_two_device_calibration({intrinsics, extrinsics});
  EXPECT_TRUE(devices) << devices.status().message();
  auto calibration = stereo_calibration(*devices, {160, 128});
  EXPECT_TRUE(calibration) << calibration.status().message();
  StereoOptions options;
  options.projector_width = 912;
  auto reconstructor = StereoReconstructor::create(*calibration, options);
  EXPECT_TRUE(reconstructor) << reconstructor.status().message();
  FringeSet l, r;
  l.images = left.images;
  r.images = right.images;
  auto scan = reconstructor->reconstruct(l, r, **set);
  EXPECT_TRUE(scan) << scan.status().message();
  if (!scan) return {};
  EXPECT_TRUE(scan->check());
  const fixture::DepthError e = fixture::depth_error(*scan, left.truth);
  std::printf("%s: RMS %.3f mm, max %.2f mm, valid %.4f (%d px)\n", pattern.c_str(), e.rms_mm,
              e.max_mm, e.valid_share, e.compared);
  return e;
}

// Depth from a 160-px-wide camera pair is noisier than from the projector-camera pair: at 650 mm
// one camera pixel of disparity is 11.8 mm (f = 299 px, 120 mm apart), one projector pixel of the
// rig 1.6 mm. The errors are unbiased (median -0.006 mm, 5-95 % range -0.91 .. 0.91 mm for
// mf4-f16-f1; -0.47 .. 0.48 mm for the finer cgray5-psp4).
TEST(StereoPair, ToedInDistortedPairIsRectifiedAndMatched) {
  const Pair pair = make_pair(120, 6, {-0.08, 0.02, 0, 0, 0});
  testing::TempDir dir;
  const fixture::DepthError e = run(pair, "mf4-f16-f1", dir);
  EXPECT_LT(e.rms_mm, 0.8);
  EXPECT_GT(e.valid_share, 0.78);  // the rest of the left view is outside the right camera's
}

TEST(StereoPair, RectifiedPairAndAComplementaryGrayCode) {
  const Pair pair = make_pair(120, 0, {});
  testing::TempDir dir;
  const fixture::DepthError e = run(pair, "cgray5-psp4", dir);
  EXPECT_LT(e.rms_mm, 0.5);
  EXPECT_GT(e.valid_share, 0.65);  // parallel cameras share less of the view
}

// The same through gvkit reconstruct: a folder with left/ and right/, the calibration as two
// files.
TEST(StereoPair, ReconstructCommandReadsALeftRightFolder) {
  testing::TempDir dir;
  const fixture::DepthError direct =
      run(make_pair(120, 6, {-0.08, 0.02, 0, 0, 0}), "mf4-f16-f1", dir);
  const std::string calibration = " --calibration " + (dir / "intrinsics.yml").string() + "," +
                                  (dir / "extrinsics.yml").string();
  auto r =
      testing::run_gvkit("reconstruct " + dir.path().string() + " -o " + (dir / "out").string() +
                         " --pattern mf4-f16-f1 --projector-size "
                         "912x570 --no-progress --ground-truth " +
                         (dir / "gt").string() + calibration);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(testing::contains(r.output, "a camera pair (left/right)")) << r.output;
  auto stats = read_json(dir / "out" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_NEAR((*stats)["summary"]["mean_valid_share"].get<double>(), direct.valid_share, 0.25);
  EXPECT_EQ((*stats)["options"]["calibration_note"], "camera pair left/right");
  // Every compared pixel, silhouette and shadow edges included.
  EXPECT_LT((*stats)["summary"]["rms_depth_error_mm"].get<double>(), 1.5) << stats->dump();
  // A spatially unwrapped set is refused before anything is written.
  auto spatial = testing::run_gvkit("reconstruct " + dir.path().string() + " -o " +
                                    (dir / "out2").string() + " --pattern psp8-f16" + calibration);
  ASSERT_NE(spatial.exit_code, 0);
  EXPECT_TRUE(testing::contains(spatial.output, "needs an absolute pattern set")) << spatial.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out2"));
  // One camera short of an image.
  std::filesystem::remove(dir / "right" / "capture_8.bmp");
  auto short_right =
      testing::run_gvkit("reconstruct " + dir.path().string() + " -o " + (dir / "out3").string() +
                         " --pattern mf4-f16-f1" + calibration);
  ASSERT_NE(short_right.exit_code, 0);
  EXPECT_TRUE(testing::contains(short_right.output, "right")) << short_right.output;
}

TEST(StereoPair, SpatiallyUnwrappedPatternsAreRefused) {
  const Pair pair = make_pair(120, 0, {});
  StereoCalibration c;
  c.left_K = c.right_K = pair.left.camera_K;
  c.size = {160, 128};
  c.R_right_from_left = pair.R_right_from_left;
  c.t_right_from_left_mm = pair.t_right_from_left_mm;
  auto reconstructor = StereoReconstructor::create(c);
  ASSERT_TRUE(reconstructor) << reconstructor.status().message();
  auto set = create_pattern_set("psp4-f16");
  FringeSet f;
  for (int k = 0; k < 4; ++k) f.images.emplace_back(128, 160, CV_8U, cv::Scalar(40 + 30 * k));
  auto r = reconstructor->reconstruct(f, f, **set);
  ASSERT_FALSE(r);
  EXPECT_NE(r.status().message().find("absolute pattern set"), std::string::npos)
      << r.status().message();
  FringeSet small;
  small.images.assign(4, cv::Mat(64, 80, CV_8U, cv::Scalar(0)));
  auto s = reconstructor->reconstruct(f, small, **set);
  ASSERT_FALSE(s);
  EXPECT_NE(s.status().message().find("right camera images are 80x64"), std::string::npos)
      << s.status().message();
}

}  // namespace
}  // namespace gvkit::capture
