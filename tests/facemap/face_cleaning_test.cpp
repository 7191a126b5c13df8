// The clean stage end to end: synthetic ICT scans (detected and given landmarks), ICT meshes,
// and bad input reported per frame.
#include "gvkit/facemap/face_cleaning.hpp"

#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "gvkit/facemap/face_boundaries.hpp"
#include "gvkit/facemap/face_features.hpp"
#include "gvkit/facemap/landmark_detector.hpp"
#include "gvkit/facemap/landmark_tracker.hpp"
#include "gvkit/facemap/nearest_vertices.hpp"
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

// An open mouth as a real scanner sees it: the teeth and the mouth interior behind the lips are
// valid pixels inside the inner lip contour, `depth_mm` behind the lips' landmarks. The inner lip
// landmarks then lift onto that interior, not onto the lips.
SyntheticFaceScan open_mouth_scan(const IctFaceModel& model, double depth_mm) {
  SyntheticFaceScan s =
      render_synthetic_face_scan(model, model.evaluate({{"jawOpen", 0.6}}), small_scan());
  std::vector<cv::Point2f> lips;
  float lip_depth = 0.0f;
  for (int i : kInnerMouthContour) {
    lips.push_back(s.landmarks.points_px[i]);
    lip_depth += s.landmarks.points_mm[i][2] / kInnerMouthContour.size();
  }
  // The interior reaches a pixel past the lip contour (under the lips, as teeth do).
  for (int y = 0; y < s.scan.valid.rows; ++y)
    for (int x = 0; x < s.scan.valid.cols; ++x) {
      if (s.scan.valid.at<uint8_t>(y, x)) continue;
      if (cv::pointPolygonTest(lips, cv::Point2f(x, y), true) < -1.0) continue;
      const float x_mm = (x - (s.scan.valid.cols - 1) / 2.0f) * 1.2f;
      const float y_mm = (y - (s.scan.valid.rows - 1) / 2.0f) * 1.2f;
      s.scan.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(x_mm, y_mm, lip_depth + depth_mm);
      s.scan.valid.at<uint8_t>(y, x) = 255;
      s.scan.quality.at<float>(y, x) = 1.0f;
    }
  return s;
}

TEST_F(FaceCleaningTest, OpenMouthWithTheInteriorInTheScanGivesFourBoundaries) {
  if (!model_) GTEST_SKIP() << "../shared/data is absent; this test needs it";
  // 25 mm: the interior is a separate surface; 3 mm: it joins the lips (no depth jump).
  for (const double depth_mm : {25.0, 3.0}) {
    for (const bool cut : {true, false}) {
      if (depth_mm < 10 && !cut) continue;  // a joined interior needs the cut
      SCOPED_TRACE("interior " + std::to_string(depth_mm) + " mm behind, cut " +
                   std::to_string(cut));
      const SyntheticFaceScan s = open_mouth_scan(*model_, depth_mm);
      FaceLandmarks landmarks;
      landmarks.points_px = s.landmarks.points_px;
      CleanOptions options;
      options.cut_feature_interiors = cut;
      auto face = clean_scan(s.scan, landmarks, options);
      ASSERT_TRUE(face.is_ok()) << face.status().message();
      if (cut) {
        EXPECT_GT(face->stats.feature_pixels_removed, 50);
      }
      EXPECT_LE(face->stats.landmark_max_snap_px, options.landmark_max_gap_px);
      // The inner lip landmarks land on the lips, near the true ones, not on the interior.
      double worst = 0.0;
      for (int i : kInnerMouthContour)
        worst = std::max(worst, cv::norm(face->landmarks.points_mm[i] - s.landmarks.points_mm[i]));
      EXPECT_LT(worst, 3.0);
      // What facemap map needs: four boundary loops named by the landmarks.
      auto boundaries = find_face_boundaries(face->mesh, face->landmarks);
      EXPECT_TRUE(boundaries.is_ok()) << boundaries.status().message();
    }
  }
}

// The eye and mouth openings left unfilled (the default) give the face the mask gives with them
// filled (the reference): the regions enclose them, so the distances outside are the same.
TEST_F(FaceCleaningTest, OpenFeatureHolesGiveTheFaceOfTheFilledOnes) {
  if (!model_) GTEST_SKIP() << "../shared/data is absent; this test needs it";
  for (const double jaw : {0.0, 0.3}) {
    SCOPED_TRACE("jawOpen " + std::to_string(jaw));
    const SyntheticFaceScan s =
        render_synthetic_face_scan(*model_, model_->evaluate({{"jawOpen", jaw}}), small_scan());
    FaceLandmarks landmarks;
    landmarks.points_px = s.landmarks.points_px;
    CleanOptions reference_options;
    reference_options.fill_feature_holes = true;
    auto open = clean_scan(s.scan, landmarks);
    auto filled = clean_scan(s.scan, landmarks, reference_options);
    ASSERT_TRUE(open.is_ok()) << open.status().message();
    ASSERT_TRUE(filled.is_ok()) << filled.status().message();
    EXPECT_GE(open->stats.feature_holes_open, 2);  // the eyes; the mouth when open
    EXPECT_EQ(filled->stats.feature_holes_open, 0);
    EXPECT_EQ(open->stats.holes_filled + open->stats.feature_holes_open,
              filled->stats.holes_filled);
    EXPECT_LT(open->stats.vertices_added, filled->stats.vertices_added);
    for (int i = 0; i < FaceLandmarks::kCount; ++i)
      EXPECT_EQ(open->landmarks.points_mm[i], filled->landmarks.points_mm[i]) << "landmark " << i;
    const MeshTopology a = mesh_topology(open->mesh), b = mesh_topology(filled->mesh);
    EXPECT_EQ(a.boundary_loops, 4);
    EXPECT_EQ(b.boundary_loops, 4);
    EXPECT_EQ(a.genus, 0);
    EXPECT_EQ(a.components, 1);
    EXPECT_TRUE(find_face_boundaries(open->mesh, open->landmarks).is_ok());
    // Vertex by vertex: the same positions away from the eye and mouth boundaries. Those differ
    // by up to a margin: with a fill, a contour path can run across the fill instead of along the
    // opening's rim, so a sliver of fill stays outside the region; and the rim can slide where it
    // meets the scan's border.
    std::vector<Mesh::Point> points;
    for (auto v : open->mesh.vertices()) points.push_back(open->mesh.point(v));
    std::vector<double> d;
    nearest_vertices(filled->mesh, points, &d);
    int same = 0;
    double mean = 0.0;
    for (double x : d) {
      same += x < 1e-9;
      mean += x / static_cast<double>(d.size());
    }
    auto area = [](const Mesh& mesh) {
      double sum = 0.0;
      for (auto f : mesh.faces()) sum += mesh.calc_face_area(f);
      return sum;
    };
    const double area_ratio = area(open->mesh) / area(filled->mesh);
    std::printf(
        "jawOpen %.1f: %zu / %zu vertices, %d identical, mean offset %.3f mm, area ratio "
        "%.4f, loops %d %d %d %d / %d %d %d %d edges\n",
        jaw, points.size(), filled->mesh.n_vertices(), same, mean, area_ratio,
        a.boundary_loop_lengths[0], a.boundary_loop_lengths[1], a.boundary_loop_lengths[2],
        a.boundary_loop_lengths[3], b.boundary_loop_lengths[0], b.boundary_loop_lengths[1],
        b.boundary_loop_lengths[2], b.boundary_loop_lengths[3]);
    EXPECT_GT(same, 0.95 * static_cast<double>(points.size()));
    EXPECT_LT(mean, 0.05);
    EXPECT_NEAR(area_ratio, 1.0, 0.01);
    // The boundaries' length in mm (their edge counts depend on how the fill is triangulated
    // where a reference boundary crosses it). The eye and mouth loops may lie up to their margin
    // (1 and 2 mm) apart all round, which alone is about 2 pi (1 + 1 + 2) = 25 mm of some
    // 1,250 mm, and the rim can slide at the scan's border: 3.2 % seen with an open mouth.
    auto boundary_mm = [](const Mesh& mesh) {
      double sum = 0.0;
      for (auto h : mesh.halfedges())
        if (mesh.is_boundary(h)) sum += mesh.calc_edge_length(h);
      return sum;
    };
    const double boundary_a = boundary_mm(open->mesh), boundary_b = boundary_mm(filled->mesh);
    std::printf("boundary length %.1f / %.1f mm\n", boundary_a, boundary_b);
    EXPECT_NEAR(boundary_a, boundary_b, 0.05 * boundary_b);
  }
}

// A frame the mask refuses with the openings open is filled completely and masked again, so it
// fails (or not) exactly as with every hole filled, with the same message.
TEST_F(FaceCleaningTest, OpenFeatureHolesFailLikeTheFilledOnes) {
  if (!model_) GTEST_SKIP() << "../shared/data is absent; this test needs it";
  const SyntheticFaceScan s =
      render_synthetic_face_scan(*model_, model_->evaluate({{"jawOpen", 0.3}}), small_scan());
  FaceLandmarks landmarks;
  landmarks.points_px = s.landmarks.points_px;
  CleanOptions open_options;
  open_options.mask.radius_mm = 12.0;  // the eyes' and the mouth's balls do not join
  CleanOptions reference_options = open_options;
  reference_options.fill_feature_holes = true;
  auto open = clean_scan(s.scan, landmarks, open_options);
  auto filled = clean_scan(s.scan, landmarks, reference_options);
  ASSERT_FALSE(open.is_ok());
  ASSERT_FALSE(filled.is_ok());
  EXPECT_EQ(open.status().message(), filled.status().message());
  EXPECT_NE(open.status().message().find("expected 1 component, genus 0, 4 boundary loops"),
            std::string::npos)
      << open.status().message();
}

TEST_F(FaceCleaningTest, MeshLandmarksOffTheSurfaceAreSnappedWithinTheBound) {
  if (!model_) GTEST_SKIP() << "../shared/data is absent; this test needs it";
  const auto positions = model_->evaluate({{"jawOpen", 0.3}});
  FaceLandmarks landmarks;
  for (int v : model_->landmark_vertices()) landmarks.points_mm.emplace_back(positions[v]);
  // The nose tip 4 mm in front of the surface: moved onto it, and reported.
  FaceLandmarks near = landmarks;
  near.points_mm[FaceLandmarks::kNoseTip][2] += 4.0f;
  auto face = clean_mesh(model_->face_mesh(positions), near, "ict.obj");
  ASSERT_TRUE(face.is_ok()) << face.status().message();
  EXPECT_EQ(face->stats.landmarks_snapped_mm, 1);
  EXPECT_NEAR(face->stats.landmark_max_snap_mm, 4.0, 1.0);
  EXPECT_LT(cv::norm(face->landmarks.points_mm[FaceLandmarks::kNoseTip] -
                     landmarks.points_mm[FaceLandmarks::kNoseTip]),
            1.5);
  // 20 mm off: beyond the bound, an error naming the landmark and the bound.
  FaceLandmarks far = landmarks;
  far.points_mm[FaceLandmarks::kNoseTip][2] += 20.0f;
  face = clean_mesh(model_->face_mesh(positions), far, "ict.obj");
  ASSERT_FALSE(face.is_ok());
  EXPECT_NE(face.status().message().find("ict.obj: landmark 30 lies 20 mm off the mesh (limit 8"),
            std::string::npos)
      << face.status().message();
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
