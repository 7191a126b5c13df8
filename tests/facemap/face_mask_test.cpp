// Geodesic face mask on the ICT face: topology, radius, and bad input.
#include "gvkit/facemap/face_mask.hpp"

#include <cstdio>

#include <gtest/gtest.h>

#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/facemap/hole_filling.hpp"
#include "support/test_support.hpp"

namespace gvkit::facemap {
namespace {

struct IctFace {
  Mesh mesh;  // eyes and mouth filled: one boundary loop
  FaceLandmarks landmarks;
};

IctFace ict_face(const IctFaceModel& model, const std::vector<cv::Vec3d>& positions) {
  IctFace face;
  face.mesh = model.face_mesh(positions);
  auto filled = fill_holes(&face.mesh);
  EXPECT_TRUE(filled.is_ok()) << filled.status().message();
  for (int v : model.landmark_vertices()) face.landmarks.points_mm.emplace_back(positions[v]);
  return face;
}

TEST(FaceMask, IctFaceGivesOneSurfaceWithFourBoundaries) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen"});
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  auto area = [](const Mesh& mesh) {
    double sum = 0.0;
    for (auto f : mesh.faces()) sum += mesh.calc_face_area(f);
    return sum;
  };
  for (double jaw : {0.0, 0.6}) {
    const IctFace face = ict_face(*model, model->evaluate({{"jawOpen", jaw}}));
    // The heat method (the reference) and fast marching (the default) keep nearly the same
    // surface; fast marching's is a few percent larger, as the heat method's distances run
    // long by 1-2 % (geodesic_distance_test: fast marching is the closer to exact there).
    FaceMaskOptions heat_options;
    heat_options.method = GeodesicMethod::kHeat;
    auto heat = geodesic_face_mask(face.mesh, face.landmarks, heat_options);
    ASSERT_TRUE(heat.is_ok()) << "jawOpen " << jaw << ": " << heat.status().message();
    EXPECT_EQ(heat->topology.boundary_loops, 4);
    auto mask = geodesic_face_mask(face.mesh, face.landmarks);
    ASSERT_TRUE(mask.is_ok()) << "jawOpen " << jaw << ": " << mask.status().message();
    EXPECT_GT(area(mask->mesh) / area(heat->mesh), 0.99);
    EXPECT_LT(area(mask->mesh) / area(heat->mesh), 1.08);
    EXPECT_EQ(mask->topology.components, 1);
    EXPECT_EQ(mask->topology.genus, 0);
    EXPECT_EQ(mask->topology.boundary_loops, 4);
    EXPECT_GT(mask->radius_mm, 40.0);
    EXPECT_LT(mask->radius_mm, 120.0);
    EXPECT_LT(mask->cropped_vertices, static_cast<int>(face.mesh.n_vertices()));
    // Every vertex of the result lies within the radius (Euclidean, a lower bound of geodesic)
    // of some feature landmark; the nose tip is kept.
    const cv::Vec3f nose = face.landmarks.points_mm[FaceLandmarks::kNoseTip];
    double nearest_to_nose = 1e9;
    for (auto v : mask->mesh.vertices()) {
      const auto p = mask->mesh.point(v);
      nearest_to_nose =
          std::min(nearest_to_nose, (p - Mesh::Point(nose[0], nose[1], nose[2])).norm());
    }
    EXPECT_LT(nearest_to_nose, 3.0);
    std::printf("jawOpen %.1f: radius %.1f mm, %zu vertices, loops %d %d %d %d\n", jaw,
                mask->radius_mm, mask->mesh.n_vertices(), mask->topology.boundary_loop_lengths[0],
                mask->topology.boundary_loop_lengths[1], mask->topology.boundary_loop_lengths[2],
                mask->topology.boundary_loop_lengths[3]);
  }
}

TEST(FaceMask, TooSmallRadiusIsAClearError) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen"});
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  const IctFace face = ict_face(*model, model->neutral_mm());
  FaceMaskOptions options;
  options.radius_mm = 4.0;  // the eyes and the mouth do not even join
  auto mask = geodesic_face_mask(face.mesh, face.landmarks, options);
  ASSERT_FALSE(mask.is_ok());
  EXPECT_NE(mask.status().message().find("expected 1 component, genus 0, 4 boundary loops"),
            std::string::npos)
      << mask.status().message();
}

TEST(FaceMask, LandmarkOffTheMeshIsAnError) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen"});
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  IctFace face = ict_face(*model, model->neutral_mm());
  face.landmarks.points_mm[40][2] += 50.0f;
  auto mask = geodesic_face_mask(face.mesh, face.landmarks);
  ASSERT_FALSE(mask.is_ok());
  EXPECT_NE(mask.status().message().find("landmark 40"), std::string::npos)
      << mask.status().message();
}

TEST(FaceMask, OptionsAreChecked) {
  FaceMaskOptions options;
  EXPECT_TRUE(options.check().is_ok());
  options.radius_mm = -1;
  EXPECT_FALSE(options.check().is_ok());
}

}  // namespace
}  // namespace gvkit::facemap
