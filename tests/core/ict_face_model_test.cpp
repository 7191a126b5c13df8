#include "gvkit/core/ict_face_model.hpp"

#include <gtest/gtest.h>

#include "gvkit/core/mesh_topology.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {

TEST(IctFaceModel, LoadsNeutralExpressionsAndLandmarks) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen", "eyeBlink_L"});
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  EXPECT_EQ(model->neutral_mm().size(), 26719u);
  EXPECT_EQ(model->polygons().size(), 26384u);
  EXPECT_EQ(model->expression_names(), (std::vector<std::string>{"eyeBlink_L", "jawOpen"}));
  // Millimetres: the neutral face is about 15-25 cm tall.
  double lo = 1e9, hi = -1e9;
  for (int v = 0; v < IctFaceModel::kFaceVertexCount; ++v) {
    lo = std::min(lo, model->neutral_mm()[v][1]);
    hi = std::max(hi, model->neutral_mm()[v][1]);
  }
  EXPECT_GT(hi - lo, 150.0);
  EXPECT_LT(hi - lo, 350.0);
  // Opening the jaw moves the chin landmark (8) down by centimetres, the nose tip (30) barely.
  const auto open = model->evaluate({{"jawOpen", 1.0}});
  const int chin = model->landmark_vertices()[8], nose = model->landmark_vertices()[30];
  EXPECT_GT(cv::norm(open[chin] - model->neutral_mm()[chin]), 10.0);
  EXPECT_LT(cv::norm(open[nose] - model->neutral_mm()[nose]), 3.0);
  EXPECT_THROW(model->evaluate({{"noSuchShape", 1.0}}), ContractError);
}

TEST(IctFaceModel, FaceAreaIsGenusZeroWithFourBoundaries) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen"});
  ASSERT_TRUE(model.is_ok());
  const Mesh face = model->face_mesh(model->neutral_mm());
  const MeshTopology t = mesh_topology(face);
  EXPECT_EQ(face.n_vertices(), 9409u);
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.boundary_loops, 4);
  EXPECT_EQ(t.genus, 0);
}

TEST(IctFaceModel, MissingFolderIsNamed) {
  auto model = IctFaceModel::load("/nonexistent/ict");
  ASSERT_FALSE(model.is_ok());
  EXPECT_NE(model.status().message().find("generic_neutral_mesh.obj"), std::string::npos);
}

}  // namespace
}  // namespace gvkit
