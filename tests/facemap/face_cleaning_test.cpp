// The clean stage end to end: synthetic ICT scans (detected and given landmarks), ICT meshes,
// and bad input reported per frame.
#include "gvkit/facemap/face_cleaning.hpp"

#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>

#include "gvkit/facemap/landmark_detector.hpp"
#include "gvkit/facemap/landmark_tracker.hpp"
#include "gvkit/facemap/synthetic_face_scan.hpp"
#include "support/test_support.hpp"

namespace gvkit::facemap {
namespace {

// Small scans keep the suite fast (also under sanitizers): 176 px at 1.2 mm, about 17K vertices.
SyntheticFaceScanOptions small_scan() {
  SyntheticFaceScanOptions o;
  o.size_px = 176;
  o.pixel_mm = 1.2;
  return o;
}

class FaceCleaningTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto dir = ::gvkit::testing::shared_data_dir();
    if (dir.empty()) return;
    auto model = IctFaceModel::load(dir / "ict-facekit", {"jawOpen", "mouthSmile_L"});
    ASSERT_TRUE(model.is_ok()) << model.status().message();
    model_ = new IctFaceModel(std::move(model).value());
  }
  static void TearDownTestSuite() {
    delete model_;
    model_ = nullptr;
  }
  static IctFaceModel* model_;
};
IctFaceModel* FaceCleaningTest::model_ = nullptr;

TEST_F(FaceCleaningTest, SyntheticScanWithTrueLandmarksGivesFourBoundaries) {
  if (!model_) GTEST_SKIP() << "../shared/data is absent; this test needs it";
  const SyntheticFaceScan synthetic =
      render_synthetic_face_scan(*model_, model_->neutral_mm(), small_scan());
  FaceLandmarks landmarks;
  landmarks.points_px = synthetic.landmarks.points_px;
  auto face = clean_scan(synthetic.scan, landmarks);
  ASSERT_TRUE(face.is_ok()) << face.status().message();
  EXPECT_EQ(face->landmarks.points_mm.size(), 68u);
  // Lifted landmarks lie near the true 3D landmarks (they sit on the eye and mouth hole rims of
  // the scan, so the nearest valid pixel can be a pixel or two away).
  double sum = 0.0;
  for (int i = 27; i < 36; ++i)
    sum += cv::norm(face->landmarks.points_mm[i] - synthetic.landmarks.points_mm[i]);
  EXPECT_LT(sum / 9.0, 1.0);  // nose: fully inside the valid scan
  EXPECT_GT(face->stats.holes_filled, 0);
  EXPECT_GT(face->stats.output_vertices, 1000);
  std::printf("mesh %.0f fill %.0f mask %.0f ms\n", face->stats.mesh_ms, face->stats.fill_ms,
              face->stats.mask_ms);
  std::printf("synthetic scan: %d -> %d vertices, %d holes filled, radius %.1f mm, %.0f ms\n",
              face->stats.input_vertices, face->stats.output_vertices, face->stats.holes_filled,
              face->stats.radius_mm, face->stats.total_ms);
}

TEST_F(FaceCleaningTest, DlibFindsTheSyntheticFaceLandmarks) {
  if (!model_) GTEST_SKIP() << "../shared/data is absent; this test needs it";
  if (!std::filesystem::exists(kDefaultShapePredictorPath)) GTEST_SKIP() << "no dlib model";
  auto detector = LandmarkDetector::create();
  ASSERT_TRUE(detector.is_ok()) << detector.status().message();
  const SyntheticFaceScan synthetic =
      render_synthetic_face_scan(*model_, model_->neutral_mm(), small_scan());
  auto detected = detector->detect(synthetic.scan.texture);
  ASSERT_TRUE(detected.is_ok()) << detected.status().message();
  double all = 0.0, inner = 0.0;
  for (int i = 0; i < 68; ++i) {
    const double e = cv::norm(detected->points_px[i] - synthetic.landmarks.points_px[i]);
    all += e;
    if (i >= 27) inner += e;
  }
  std::printf("dlib on the synthetic ICT render: mean error %.2f px (all 68), %.2f px (27-67)\n",
              all / 68, inner / 41);
  EXPECT_LT(inner / 41, 6.0);
  // And the whole stage runs on the detected landmarks.
  auto face = clean_scan(synthetic.scan, std::move(detected).value());
  EXPECT_TRUE(face.is_ok()) << face.status().message();
}

TEST_F(FaceCleaningTest, TrackerFollowsAnExpressionChange) {
  if (!model_) GTEST_SKIP() << "../shared/data is absent; this test needs it";
  const auto a =
      render_synthetic_face_scan(*model_, model_->evaluate({{"mouthSmile_L", 0.0}}), small_scan());
  const auto b =
      render_synthetic_face_scan(*model_, model_->evaluate({{"mouthSmile_L", 0.3}}), small_scan());
  LandmarkTracker tracker(a.scan.texture, a.landmarks, nullptr);
  auto tracked = tracker.track(b.scan.texture);
  ASSERT_TRUE(tracked.is_ok()) << tracked.status().message();
  double sum = 0.0;
  for (int i = 27; i < 68; ++i) sum += cv::norm(tracked->points_px[i] - b.landmarks.points_px[i]);
  std::printf("LK tracking, smile 0 -> 0.3: mean error %.2f px (27-67)\n", sum / 41);
  EXPECT_LT(sum / 41, 2.0);
}

TEST_F(FaceCleaningTest, IctMeshWithHolesGivesFourBoundaries) {
  if (!model_) GTEST_SKIP() << "../shared/data is absent; this test needs it";
  const auto positions = model_->evaluate({{"jawOpen", 0.3}});
  FaceLandmarks landmarks;
  for (int v : model_->landmark_vertices()) landmarks.points_mm.emplace_back(positions[v]);
  auto face = clean_mesh(model_->face_mesh(positions), landmarks, "ict.obj");
  ASSERT_TRUE(face.is_ok()) << face.status().message();
  EXPECT_EQ(face->stats.holes_filled, 3);
}

TEST(FaceCleaning, SeveralComponentsAreAnErrorNamingTheInput) {
  Mesh mesh;
  for (int c = 0; c < 2; ++c) {
    auto a = mesh.add_vertex({100.0 * c, 0, 0}), b = mesh.add_vertex({100.0 * c + 1, 0, 0}),
         d = mesh.add_vertex({100.0 * c, 1, 0});
    mesh.add_face(a, b, d);
  }
  FaceLandmarks landmarks;
  landmarks.points_mm.assign(68, cv::Vec3f(0, 0, 0));
  auto face = clean_mesh(mesh, landmarks, "two.ply");
  ASSERT_FALSE(face.is_ok());
  EXPECT_NE(face.status().message().find("two.ply: mesh has 2 connected components"),
            std::string::npos)
      << face.status().message();
}

TEST_F(FaceCleaningTest, LandmarksOutsideTheValidScanAreAnErrorNamingTheFrame) {
  if (!model_) GTEST_SKIP() << "../shared/data is absent; this test needs it";
  SyntheticFaceScan synthetic =
      render_synthetic_face_scan(*model_, model_->neutral_mm(), small_scan());
  synthetic.scan.index = 12;
  FaceLandmarks landmarks;
  landmarks.points_px = synthetic.landmarks.points_px;
  for (auto& p : landmarks.points_px) p.x += 200;  // off the face
  auto face = clean_scan(synthetic.scan, landmarks);
  ASSERT_FALSE(face.is_ok());
  EXPECT_NE(face.status().message().find("frame 12: landmark"), std::string::npos)
      << face.status().message();
}

}  // namespace
}  // namespace gvkit::facemap
