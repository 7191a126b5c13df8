// Landmarks of a mesh from dlib on its frontal render, lifted onto the surface: against the ICT
// landmark vertices on the ICT neutral face, whatever the mesh's pose; no face is an error naming
// the mesh.
#include "gvkit/facemap/mesh_landmarks.hpp"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "gvkit/core/ict_face_model.hpp"
#include "support/test_support.hpp"

namespace gvkit::facemap {
namespace {

class MeshLandmarksTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!std::filesystem::exists(kDefaultShapePredictorPath)) return;
    auto d = LandmarkDetector::create();
    ASSERT_TRUE(d.is_ok()) << d.status().message();
    detector_ = new LandmarkDetector(std::move(d).value());
  }
  static void TearDownTestSuite() {
    delete detector_;
    detector_ = nullptr;
  }
  static LandmarkDetector* detector_;
};
LandmarkDetector* MeshLandmarksTest::detector_ = nullptr;

// Mean and max distance (mm) of the inner landmarks (brows, nose, eyes, mouth: 17..67; the jaw
// line of a 2D detector follows the silhouette, not fixed surface points) to the ICT vertices.
void expect_close_to_ict(const IctFaceModel& model, const std::vector<cv::Vec3d>& pos,
                         const FaceLandmarks& found, double mean_mm, const std::string& what) {
  ASSERT_EQ(found.points_mm.size(), 68u);
  double sum = 0.0, worst = 0.0;
  for (int i = 17; i < 68; ++i) {
    const double d = cv::norm(cv::Vec3d(found.points_mm[i]) - pos[model.landmark_vertices()[i]]);
    sum += d;
    worst = std::max(worst, d);
  }
  const double mean = sum / 51.0;
  std::printf("%s: inner landmarks mean %.2f mm, max %.2f mm\n", what.c_str(), mean, worst);
  EXPECT_LT(mean, mean_mm) << what;
  // Anatomy: subject's right eye (36) on the mesh's -x side of the left eye (45), nose tip
  // between the eyes and the chin in y.
  EXPECT_LT(found.points_mm[36][0], found.points_mm[45][0]) << what;
}

TEST_F(MeshLandmarksTest, IctNeutralFaceWithinFewMillimetres) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  if (!detector_) GTEST_SKIP() << "dlib model absent (package libdlib-data)";
  auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen"});
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  const auto& pos = model->neutral_mm();
  const Mesh mesh = model->face_mesh(pos);
  auto found = detect_mesh_landmarks(mesh, *detector_, "ict neutral");
  ASSERT_TRUE(found.is_ok()) << found.status().message();
  EXPECT_EQ(found->roll_deg, 0);
  expect_close_to_ict(*model, pos, found->landmarks, 4.0, "upright");
}

TEST_F(MeshLandmarksTest, UpsideDownMeshIsFoundByRolling) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  if (!detector_) GTEST_SKIP() << "dlib model absent (package libdlib-data)";
  auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen"});
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  // Rotated 180 degrees about z (y down, as in a camera frame), and moved away.
  std::vector<cv::Vec3d> pos = model->neutral_mm();
  for (auto& p : pos) p = cv::Vec3d(-p[0], -p[1], p[2]) + cv::Vec3d(20, -30, 1200);
  const Mesh mesh = model->face_mesh(pos);
  auto found = detect_mesh_landmarks(mesh, *detector_, "ict rotated");
  ASSERT_TRUE(found.is_ok()) << found.status().message();
  EXPECT_EQ(found->roll_deg, 180);
  double sum = 0.0;
  for (int i = 17; i < 68; ++i)
    sum += cv::norm(cv::Vec3d(found->landmarks.points_mm[i]) - pos[model->landmark_vertices()[i]]);
  EXPECT_LT(sum / 51.0, 4.0);
}

TEST_F(MeshLandmarksTest, NoFaceIsAnErrorNamingTheMesh) {
  if (!detector_) GTEST_SKIP() << "dlib model absent (package libdlib-data)";
  // A flat grid: renders, but holds no face.
  Mesh mesh;
  std::vector<Mesh::VertexHandle> v;
  const int n = 20;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) v.push_back(mesh.add_vertex(Mesh::Point(x * 5.0, y * 5.0, 0.0)));
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      mesh.add_face(v[y * n + x], v[y * n + x + 1], v[(y + 1) * n + x + 1]);
      mesh.add_face(v[y * n + x], v[(y + 1) * n + x + 1], v[(y + 1) * n + x]);
    }
  auto found = detect_mesh_landmarks(mesh, *detector_, "flat.ply");
  ASSERT_FALSE(found.is_ok());
  EXPECT_NE(found.status().message().find("flat.ply"), std::string::npos);
  EXPECT_NE(found.status().message().find("no face"), std::string::npos);
}

TEST(MeshRender, PixelOfMatchesTheRasterizedTriangle) {
  // One triangle seen from +z: its centroid's pixel is covered by it.
  Mesh mesh;
  auto a = mesh.add_vertex(Mesh::Point(0, 0, 0));
  auto b = mesh.add_vertex(Mesh::Point(10, 0, 0));
  auto c = mesh.add_vertex(Mesh::Point(0, 10, 0));
  mesh.add_face(a, b, c);
  const MeshRender r = render_mesh(mesh, {0, 0, 1}, {0, 1, 0});
  const cv::Vec2d p = r.pixel_of({10.0 / 3, 10.0 / 3, 0});
  EXPECT_EQ(
      r.triangle.at<int>(static_cast<int>(std::lround(p[1])), static_cast<int>(std::lround(p[0]))),
      0);
  // Up is up: the vertex at +y is above (smaller row than) the one at +x.
  EXPECT_LT(r.pixel_of({0, 10, 0})[1], r.pixel_of({10, 0, 0})[1]);
  EXPECT_EQ(r.triangle.at<int>(0, r.image.cols - 1), -1);
}

TEST(MeshLandmarkOptions, BadValuesAreRejected) {
  MeshLandmarkOptions o;
  o.render.size_px = 10;
  EXPECT_FALSE(o.check().is_ok());
  o = {};
  o.max_gap_px = -1;
  EXPECT_FALSE(o.check().is_ok());
  EXPECT_TRUE(MeshLandmarkOptions{}.check().is_ok());
}

}  // namespace
}  // namespace gvkit::facemap
