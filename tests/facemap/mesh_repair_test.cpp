// Mesh repair: duplicate and degenerate faces, non-manifold edges, several components.
#include "gvkit/facemap/mesh_repair.hpp"

#include <gtest/gtest.h>

#include "gvkit/core/mesh_topology.hpp"

namespace gvkit::facemap {
namespace {

TEST(MeshRepair, RemovesDuplicatesNonManifoldFacesAndSmallComponents) {
  std::vector<Mesh::Point> p = {{0, 0, 0},     {1, 0, 0},  {1, 1, 0},  {0, 1, 0},
                                {0.5, 0.5, 1}, {10, 0, 0}, {11, 0, 0}, {10, 1, 0}};
  std::vector<std::array<int, 3>> t = {
      {0, 1, 2}, {0, 2, 3},  // a square
      {2, 1, 0},             // duplicate (reversed)
      {0, 2, 4},             // third face on edge 0-2: non-manifold
      {1, 1, 2},             // degenerate
      {5, 6, 7},             // a second component
  };
  MeshRepairReport report;
  const Mesh mesh = mesh_from_triangles(p, {}, t, {}, &report);
  EXPECT_EQ(report.duplicate_faces, 1);
  EXPECT_EQ(report.degenerate_faces, 1);
  EXPECT_EQ(report.non_manifold_faces, 1);
  EXPECT_EQ(report.components, 2);
  EXPECT_EQ(report.removed_component_faces, 1);
  EXPECT_EQ(mesh.n_faces(), 2u);
  EXPECT_EQ(mesh.n_vertices(), 4u);  // vertex 4 lost its only face
  EXPECT_TRUE(report.changed());
  EXPECT_NE(report.summary().find("duplicate"), std::string::npos) << report.summary();
  EXPECT_EQ(mesh_topology(mesh).components, 1);
}

TEST(MeshRepair, CleanMeshIsUnchanged) {
  Mesh mesh;
  auto a = mesh.add_vertex({0, 0, 0}), b = mesh.add_vertex({1, 0, 0}),
       c = mesh.add_vertex({0, 1, 0});
  mesh.add_face(a, b, c);
  const MeshRepairReport report = repair_mesh(&mesh);
  EXPECT_FALSE(report.changed()) << report.summary();
  EXPECT_EQ(mesh.n_faces(), 1u);
}

}  // namespace
}  // namespace gvkit::facemap
