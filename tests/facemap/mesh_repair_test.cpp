// Mesh repair: duplicate and degenerate faces, non-manifold edges, several components.
#include "gvkit/facemap/mesh_repair.hpp"

#include <algorithm>
#include <random>

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

// Grid triangles over a random mask of valid pixels (holes, pinches where only diagonal
// neighbours are valid), like a range scan's.
void random_grid(int n, double p_valid, unsigned seed, std::vector<Mesh::Point>* points,
                 std::vector<std::array<int, 3>>* triangles) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution valid(p_valid);
  std::vector<int> index(n * n, -1);
  for (int i = 0; i < n * n; ++i)
    if (valid(rng)) {
      index[i] = static_cast<int>(points->size());
      points->emplace_back(i % n, i / n, 0.01 * ((i * 7919) % 13));
    }
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      const int a = index[y * n + x], b = index[y * n + x + 1], c = index[(y + 1) * n + x + 1],
                d = index[(y + 1) * n + x];
      if (a >= 0 && b >= 0 && c >= 0 && d >= 0) {
        triangles->push_back({a, c, b});
        triangles->push_back({a, d, c});
      } else if (b >= 0 && c >= 0 && d >= 0) {
        triangles->push_back({b, d, c});
      } else if (a >= 0 && c >= 0 && d >= 0) {
        triangles->push_back({a, d, c});
      } else if (a >= 0 && b >= 0 && d >= 0) {
        triangles->push_back({a, d, b});
      } else if (a >= 0 && b >= 0 && c >= 0) {
        triangles->push_back({a, c, b});
      }
    }
}

// Half-edge invariants every OpenMesh traversal relies on.
void expect_consistent(const Mesh& mesh) {
  for (auto h : mesh.halfedges()) {
    ASSERT_EQ(mesh.prev_halfedge_handle(mesh.next_halfedge_handle(h)), h);
    ASSERT_EQ(mesh.from_vertex_handle(mesh.next_halfedge_handle(h)), mesh.to_vertex_handle(h));
    ASSERT_EQ(mesh.face_handle(mesh.next_halfedge_handle(h)), mesh.face_handle(h));
  }
  for (auto v : mesh.vertices()) {
    const auto h = mesh.halfedge_handle(v);
    ASSERT_TRUE(h.is_valid());
    ASSERT_EQ(mesh.from_vertex_handle(h), v);
    bool any_boundary = false;
    for (auto o : mesh.voh_range(v)) any_boundary = any_boundary || mesh.is_boundary(o);
    // A boundary vertex keeps a boundary halfedge as its outgoing one.
    if (any_boundary) {
      ASSERT_TRUE(mesh.is_boundary(h));
    }
  }
}

// The direct half-edge build against OpenMesh's add_face (the reference): same vertices, faces
// and topology; a mask with pinches (vertices with two fans) gets the same counts too.
TEST(MeshRepair, DirectBuildMatchesAddFace) {
  for (double p_valid : {1.0, 0.95, 0.8, 0.6}) {
    std::vector<Mesh::Point> points;
    std::vector<std::array<int, 3>> triangles;
    random_grid(40, p_valid, 17, &points, &triangles);
    MeshRepairOptions direct, reference;
    reference.direct_build = false;
    direct.keep_largest_component = reference.keep_largest_component = false;
    MeshRepairReport r_direct, r_reference;
    const Mesh a = mesh_from_triangles(points, {}, triangles, direct, &r_direct);
    const Mesh b = mesh_from_triangles(points, {}, triangles, reference, &r_reference);
    SCOPED_TRACE(p_valid);
    EXPECT_EQ(r_reference.non_manifold_faces, 0);
    ASSERT_EQ(a.n_vertices(), b.n_vertices());
    ASSERT_EQ(a.n_faces(), b.n_faces());
    EXPECT_EQ(a.n_edges(), b.n_edges());
    for (auto v : a.vertices()) EXPECT_EQ(a.point(v), b.point(Mesh::VertexHandle(v.idx())));
    for (auto f : a.faces()) {
      std::vector<int> fa, fb;
      for (auto v : a.fv_range(f)) fa.push_back(v.idx());
      for (auto v : b.fv_range(Mesh::FaceHandle(f.idx()))) fb.push_back(v.idx());
      // Same corners in the same cyclic order.
      std::rotate(fa.begin(), std::min_element(fa.begin(), fa.end()), fa.end());
      std::rotate(fb.begin(), std::min_element(fb.begin(), fb.end()), fb.end());
      ASSERT_EQ(fa, fb);
    }
    expect_consistent(a);
    const MeshTopology ta = mesh_topology(a), tb = mesh_topology(b);
    EXPECT_EQ(ta.components, tb.components);
    EXPECT_EQ(ta.boundary_loops, tb.boundary_loops);
    EXPECT_EQ(ta.euler_characteristic, tb.euler_characteristic);
    for (auto v : a.vertices())
      EXPECT_EQ(a.valence(v), b.valence(Mesh::VertexHandle(v.idx()))) << v.idx();
  }
}

TEST(MeshRepair, DirectBuildRefusesWhatItCannotRepresent) {
  std::vector<Mesh::Point> p = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1}};
  Mesh mesh;
  EXPECT_FALSE(build_half_edges(5, {{0, 1, 2}, {0, 2, 3}, {0, 2, 4}}, &mesh));  // 0->2 twice
  EXPECT_FALSE(build_half_edges(3, {{0, 1, 2}, {2, 1, 0}}, &mesh));             // closed pair
  EXPECT_TRUE(build_half_edges(4, {{0, 1, 2}, {0, 2, 3}}, &mesh));
  EXPECT_EQ(mesh.n_edges(), 5u);
  // The repair falls back to add_face and drops the third face on edge 0-2.
  MeshRepairReport report;
  const Mesh repaired = mesh_from_triangles(p, {}, {{0, 1, 2}, {0, 2, 3}, {0, 2, 4}}, {}, &report);
  EXPECT_EQ(report.non_manifold_faces, 1);
  EXPECT_EQ(repaired.n_faces(), 2u);
}

// Outgoing boundary halfedges per vertex: one per open fan.
std::vector<int> open_fans(const Mesh& mesh) {
  std::vector<int> fans(mesh.n_vertices(), 0);
  for (auto h : mesh.halfedges())
    if (mesh.is_boundary(h)) ++fans[mesh.from_vertex_handle(h).idx()];
  return fans;
}

// A hole touching the rim at one vertex (a bow tie of two quads missing at a corner of a grid):
// the vertex keeps one fan, the hole joins the rim, and the counts are those of a disk.
TEST(MeshRepair, OpensABoundaryPinch) {
  std::vector<Mesh::Point> points;
  std::vector<std::array<int, 3>> triangles;
  const int n = 6;
  for (int i = 0; i < n * n; ++i) points.emplace_back(i % n, i / n, 0);
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      if ((x == 0 && y == 0) || (x == 1 && y == 1)) continue;  // the two quads at vertex 7
      const int a = y * n + x, b = a + 1, c = a + n + 1, d = a + n;
      triangles.push_back({a, c, b});
      triangles.push_back({a, d, c});
    }
  MeshRepairReport report;
  std::vector<int> built;  // mesh vertex -> grid point
  Mesh mesh = mesh_from_triangles(points, {}, triangles, {}, &report, &built);
  const int pinch = static_cast<int>(std::find(built.begin(), built.end(), 7) - built.begin());
  ASSERT_EQ(open_fans(mesh)[pinch], 2);
  std::vector<int> original;
  const int removed = open_boundary_pinches(&mesh, &original);
  EXPECT_GT(removed, 0);
  EXPECT_LE(removed, 4);  // the smaller fan at the pinch, no cascade
  expect_consistent(mesh);
  for (int f : open_fans(mesh)) EXPECT_LE(f, 1);
  const MeshTopology t = mesh_topology(mesh);
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.boundary_loops, 1);
  EXPECT_EQ(t.euler_characteristic, 1);  // a disk: the Euler count no longer misses the pinch
  ASSERT_EQ(original.size(), mesh.n_vertices());
  for (auto v : mesh.vertices()) EXPECT_EQ(mesh.point(v), points[built[original[v.idx()]]]);
}

// Scan-like grids full of pinches: none is left, one component, every triangle from the input.
TEST(MeshRepair, OpensEveryPinchOfAScanLikeGrid) {
  for (unsigned seed : {3u, 11u}) {
    std::vector<Mesh::Point> points;
    std::vector<std::array<int, 3>> triangles;
    random_grid(30, 0.9, seed, &points, &triangles);
    MeshRepairReport report;
    std::vector<int> built;  // mesh vertex -> grid point
    Mesh mesh = mesh_from_triangles(points, {}, triangles, {}, &report, &built);
    const auto before = open_fans(mesh);
    ASSERT_GT(std::count_if(before.begin(), before.end(), [](int f) { return f > 1; }), 0);
    const size_t faces_before = mesh.n_faces();
    std::vector<int> original;
    const int removed = open_boundary_pinches(&mesh, &original);
    SCOPED_TRACE(seed);
    expect_consistent(mesh);
    for (int f : open_fans(mesh)) EXPECT_LE(f, 1);
    EXPECT_EQ(mesh_topology(mesh).components, 1);
    EXPECT_EQ(mesh.n_faces() + removed, faces_before);
    EXPECT_LT(removed, static_cast<int>(faces_before) / 4);
    for (auto v : mesh.vertices()) EXPECT_EQ(mesh.point(v), points[built[original[v.idx()]]]);
  }
}

// mesh_topology finds the boundary loops in its pass over the edges: the same loops as
// boundary_loops (lengths, longest first), and the same counts with the halfedge status (the
// path that calls boundary_loops), on grids with holes and pinches.
TEST(MeshTopology, LoopsAreThoseOfBoundaryLoops) {
  for (double p_valid : {1.0, 0.95, 0.8}) {
    std::vector<Mesh::Point> points;
    std::vector<std::array<int, 3>> triangles;
    random_grid(40, p_valid, 23, &points, &triangles);
    MeshRepairOptions options;
    options.keep_largest_component = false;
    MeshRepairReport report;
    Mesh mesh = mesh_from_triangles(points, {}, triangles, options, &report);
    SCOPED_TRACE(p_valid);
    const MeshTopology t = mesh_topology(mesh);
    std::vector<int> lengths;
    for (const auto& loop : boundary_loops(mesh)) lengths.push_back(static_cast<int>(loop.size()));
    EXPECT_EQ(t.boundary_loop_lengths, lengths);
    EXPECT_EQ(t.boundary_loops, static_cast<int>(lengths.size()));
    if (p_valid < 1.0) EXPECT_GT(t.boundary_loops, 2);
    mesh.request_halfedge_status();
    const MeshTopology with_status = mesh_topology(mesh);
    EXPECT_EQ(with_status.boundary_loop_lengths, t.boundary_loop_lengths);
    EXPECT_EQ(with_status.components, t.components);
    EXPECT_EQ(with_status.genus, t.genus);
    EXPECT_EQ(with_status.euler_characteristic, t.euler_characteristic);
  }
}

}  // namespace
}  // namespace gvkit::facemap
