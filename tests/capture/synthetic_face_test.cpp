// The synthetic projector-camera on the ICT face: ground truth consistency, shadows,
// determinism, and reconstruction accuracy against the truth (small images to stay fast).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "gvkit/capture/expression_track.hpp"
#include "gvkit/capture/ground_truth.hpp"
#include "gvkit/capture/ict_face_scene.hpp"
#include "gvkit/capture/reconstructor.hpp"
#include "gvkit/capture/scan_accuracy.hpp"
#include "gvkit/capture/synthetic_rig.hpp"
#include "support/test_support.hpp"

namespace gvkit::capture {
namespace {

class SyntheticFace : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto dir = testing::shared_data_dir();
    if (dir.empty()) return;
    auto scene = IctFaceScene::load(dir / "ict-facekit");
    ASSERT_TRUE(scene) << scene.status().message();
    scene_ = std::make_unique<IctFaceScene>(std::move(*scene));
  }
  static void TearDownTestSuite() { scene_.reset(); }
  void SetUp() override {
    GVKIT_REQUIRE_SHARED_DATA(data);
    SyntheticRigOptions rig;
    rig.camera_width = rig.camera_height = 224;
    rig.camera_hfov_deg = 24;  // the face fills the small image
    calibration_ = synthetic_calibration(rig);
  }

  struct Rendered {
    SyntheticScene scene;
    SyntheticFrame frame;
  };
  Rendered render(const std::string& pattern, const RenderOptions& options, uint64_t seed = 1,
                  const std::string& track = "mix", double t = 0.7) const {
    auto patterns = create_pattern_set(pattern);
    EXPECT_TRUE(patterns);
    auto expression = ExpressionTrack::create(track, 3);
    EXPECT_TRUE(expression);
    Rendered r;
    r.scene = scene_->scene(expression->at(t));
    const SyntheticRenderer renderer(calibration_, options);
    r.frame = renderer.render(
        r.scene,
        (*patterns)->generate({calibration_.projector_width, calibration_.projector_height}), seed);
    return r;
  }

  ScanAccuracy reconstruct_and_compare(const std::string& pattern, const RenderOptions& options) {
    const Rendered r = render(pattern, options);
    auto patterns = create_pattern_set(pattern);
    FringeSet f;
    f.images = r.frame.images;
    auto scan = reconstruct(f, **patterns, calibration_);
    EXPECT_TRUE(scan) << scan.status().message();
    return scan_accuracy(*scan, ground_truth_of(r.frame.truth, r.scene));
  }

  static std::unique_ptr<IctFaceScene> scene_;
  Calibration calibration_;
};
std::unique_ptr<IctFaceScene> SyntheticFace::scene_;

TEST_F(SyntheticFace, GroundTruthPointsLieOnTheTrianglesTheyName) {
  const Rendered r = render("psp3-f16", {});
  const GroundTruth gt = ground_truth_of(r.frame.truth, r.scene);
  int seen = 0, face = 0;
  for (int y = 0; y < gt.xyz_mm.rows; ++y)
    for (int x = 0; x < gt.xyz_mm.cols; ++x) {
      const cv::Vec3i v = gt.vertices.at<cv::Vec3i>(y, x);
      if (v[0] < 0) {
        EXPECT_TRUE(std::isnan(gt.xyz_mm.at<cv::Vec3f>(y, x)[2]));
        continue;
      }
      ++seen;
      face += v[0] < IctFaceModel::kFaceVertexCount;
      const cv::Vec3f b = gt.barycentric.at<cv::Vec3f>(y, x);
      EXPECT_NEAR(b[0] + b[1] + b[2], 1.0, 1e-4);
      const cv::Vec3d p = b[0] * r.scene.positions_mm[v[0]] + b[1] * r.scene.positions_mm[v[1]] +
                          b[2] * r.scene.positions_mm[v[2]];
      ASSERT_LT(cv::norm(p - cv::Vec3d(gt.xyz_mm.at<cv::Vec3f>(y, x))), 1e-3);
      // The polygon named holds the three vertices.
      const auto& polygon = scene_->model().polygons()[gt.polygon.at<int>(y, x)];
      for (int k = 0; k < 3; ++k) {
        bool found = false;
        for (const auto& c : polygon) found = found || c.vertex == v[k];
        ASSERT_TRUE(found);
      }
    }
  EXPECT_GT(seen, 224 * 224 / 4);
  EXPECT_GT(face, seen / 3);
  // The projector, 200 mm to the side, leaves part of what the camera sees in shadow.
  const int lit = cv::countNonZero(gt.lit);
  EXPECT_LT(lit, seen);
  EXPECT_GT(lit, seen * 8 / 10);
}

TEST_F(SyntheticFace, RenderingIsDeterministicFromTheSeed) {
  RenderOptions o;
  o.noise_sigma = 0.01;
  const Rendered a = render("psp3-f16", o, 5), b = render("psp3-f16", o, 5),
                 c = render("psp3-f16", o, 6);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(cv::norm(a.frame.images[k], b.frame.images[k], cv::NORM_INF), 0.0);
    EXPECT_GT(cv::norm(a.frame.images[k], c.frame.images[k], cv::NORM_INF), 0.0);
  }
}

TEST_F(SyntheticFace, BitDepthsAreStoredScaled) {
  RenderOptions o;
  o.bit_depth = 10;
  const Rendered r = render("psp3-f16", o);
  ASSERT_EQ(r.frame.images[0].depth(), CV_16U);
  // 10-bit levels scaled to 16 bits: every value is a multiple of 65535/1023 (rounded).
  for (int i = 0; i < 500; ++i) {
    const int v = r.frame.images[0].at<uint16_t>(112, 10 + i % 200);
    const double level = v * 1023.0 / 65535.0;
    EXPECT_NEAR(level, std::round(level), 0.01);
  }
}

TEST_F(SyntheticFace, ThreeStepReconstructionMatchesTruth) {
  // Noise-free 8-bit: only quantization; no pixel off by a period.
  const ScanAccuracy a = reconstruct_and_compare("psp3-f16", {});
  EXPECT_GT(a.face_interior_valid_share, 0.97);
  EXPECT_LT(a.p50_mm, 0.15);
  EXPECT_LT(a.p99_mm, 1.5);
  EXPECT_LT(a.face_interior_rms_mm, 0.4);
  EXPECT_LT(a.face_interior_max_mm, 10.0);
  EXPECT_GT(a.compared_px, 5000);
}

TEST_F(SyntheticFace, FourStepTwoFrequencyWithNoiseMatchesTruth) {
  RenderOptions o;
  o.noise_sigma = 0.01;
  o.bit_depth = 12;
  const ScanAccuracy a = reconstruct_and_compare("mf4-f16-f1", o);
  // 1 % noise at ~0.25 modulation and 16 periods: ~0.4 mm depth noise in this rig.
  EXPECT_GT(a.face_interior_valid_share, 0.97);
  EXPECT_LT(a.p50_mm, 0.8);
  EXPECT_LT(a.p99_mm, 8.0);
}

TEST_F(SyntheticFace, LandmarksProjectOntoTheFace) {
  auto track = ExpressionTrack::create("neutral", 1);
  ASSERT_TRUE(track);
  const FaceLandmarks lm = scene_->landmarks(track->at(0), calibration_);
  ASSERT_EQ(lm.points_px.size(), 68u);
  ASSERT_EQ(lm.points_mm.size(), 68u);
  // Nose tip near the image centre column and in front of the eyes.
  EXPECT_NEAR(lm.points_px[30].x, 111.5, 15);
  EXPECT_LT(lm.points_mm[30][2], lm.points_mm[36][2]);
  // Subject's right eye (36-41) appears on the image's left.
  EXPECT_LT(lm.points_px[36].x, lm.points_px[45].x);
}

TEST(ExpressionTrack, NamesWeightsAndDeterminism) {
  EXPECT_FALSE(ExpressionTrack::create("dance", 1));
  for (const auto& name : expression_track_names()) {
    auto a = ExpressionTrack::create(name, 9, true), b = ExpressionTrack::create(name, 9, true);
    ASSERT_TRUE(a && b);
    double blink_max = 0;
    for (int i = 0; i < 120; ++i) {
      const ExpressionPose p = a->at(i / 30.0), q = b->at(i / 30.0);
      EXPECT_EQ(p.weights, q.weights);
      for (const auto& [shape, w] : p.weights) {
        EXPECT_GE(w, 0.0) << shape;
        EXPECT_LE(w, 1.0) << shape;
      }
      if (p.weights.count("eyeBlink_L"))
        blink_max = std::max(blink_max, p.weights.at("eyeBlink_L"));
      EXPECT_LT(cv::norm(p.head_rotation_deg), 15.0);
    }
    if (name == "blink") {
      EXPECT_GT(blink_max, 0.9);
    }
  }
}

}  // namespace
}  // namespace gvkit::capture
