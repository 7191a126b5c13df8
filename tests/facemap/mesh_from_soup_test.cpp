// Raw triangle soups -> one repaired surface: each injected defect (duplicate faces, a fin on an
// edge, an island, a flipped patch, zero-area faces, NaN points, unreferenced points) is repaired
// and counted, the texture follows the faces through the repair, and files that are not one
// surface are refused naming the file.
#include "gvkit/facemap/mesh_from_soup.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "gvkit/core/mesh_topology.hpp"
#include "gvkit/facemap/triangle_soup_repair.hpp"
#include "support/test_support.hpp"

namespace gvkit::facemap {
namespace {
using testing::contains;

// An n x n grid of points (1 mm apart) in z = 0, two triangles per square, counter-clockwise
// seen from +z; texture coordinates (x, y) / (n - 1) on one 32 x 32 image.
TriangleSoup grid_soup(int n) {
  TriangleSoup soup;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) soup.points.emplace_back(x, y, 0.0);
  auto uv = [&](int i) {
    return cv::Vec2f(static_cast<float>(i % n) / (n - 1), static_cast<float>(i / n) / (n - 1));
  };
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      const int a = y * n + x, b = a + 1, c = a + n, d = c + 1;
      for (const auto& t : {std::array<int, 3>{a, b, d}, std::array<int, 3>{a, d, c}}) {
        soup.triangles.push_back(t);
        soup.triangle_texture.push_back(0);
        soup.corner_uv.push_back({uv(t[0]), uv(t[1]), uv(t[2])});
      }
    }
  cv::Mat image(32, 32, CV_8UC3);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x)
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(0, static_cast<uchar>(8 * x), 100);
  soup.textures = {image};
  soup.texture_paths = {"grid.png"};
  return soup;
}

void add_triangle(TriangleSoup* soup, std::array<int, 3> t) {
  soup->triangles.push_back(t);
  soup->triangle_texture.push_back(-1);
  soup->corner_uv.push_back({});
}

TEST(MeshFromSoup, CleanGridNeedsNoRepair) {
  auto m = mesh_from_soup(grid_soup(6), "grid.obj");
  ASSERT_TRUE(m.is_ok()) << m.status().message();
  EXPECT_FALSE(m->repair.changed()) << m->repair.summary();
  EXPECT_EQ(m->mesh.n_faces(), 50u);
  EXPECT_EQ(mesh_topology(m->mesh).boundary_loops, 1);
  EXPECT_TRUE(m->mesh.has_vertex_colors());  // from the texture
  ASSERT_FALSE(m->texture.empty());
}

TEST(MeshFromSoup, EveryInjectedDefectIsRepairedAndCounted) {
  const int n = 8;
  TriangleSoup soup = grid_soup(n);
  const size_t grid_faces = soup.triangles.size();
  // Duplicates: two faces repeated, one with the opposite winding.
  add_triangle(&soup, soup.triangles[3]);
  add_triangle(&soup, {soup.triangles[5][0], soup.triangles[5][2], soup.triangles[5][1]});
  // A fin: a third face on the interior edge of face 20 (its first two corners), standing up.
  soup.points.emplace_back(3.5, 1.0, 4.0);
  add_triangle(&soup, {soup.triangles[20][0], soup.triangles[20][1],
                       static_cast<int>(soup.points.size()) - 1});
  // An island of two triangles far away.
  const int i0 = static_cast<int>(soup.points.size());
  for (const auto& p : {Mesh::Point(50, 50, 0), Mesh::Point(51, 50, 0), Mesh::Point(50, 51, 0),
                        Mesh::Point(51, 51, 0)})
    soup.points.push_back(p);
  add_triangle(&soup, {i0, i0 + 1, i0 + 3});
  add_triangle(&soup, {i0, i0 + 3, i0 + 2});
  // A zero-area face: a point at the position of point 0.
  soup.points.push_back(soup.points[0]);
  add_triangle(&soup, {0, 1, static_cast<int>(soup.points.size()) - 1});
  // A repeated corner.
  add_triangle(&soup, {9, 9, 10});
  // A NaN point with two faces on it, hanging off the grid's corner.
  soup.points.emplace_back(NAN, 0.0, 0.0);
  add_triangle(&soup, {n - 1, static_cast<int>(soup.points.size()) - 1, 2 * n - 1});
  add_triangle(&soup, {n - 2, static_cast<int>(soup.points.size()) - 1, n - 1});
  // Unreferenced points.
  soup.points.emplace_back(7, 7, 7);
  soup.points.emplace_back(8, 8, 8);
  // A flipped patch: the 2 x 2 squares around (4, 4) reversed (8 faces).
  int flipped = 0;
  for (int y = 3; y < 5; ++y)
    for (int x = 3; x < 5; ++x)
      for (int k = 0; k < 2; ++k) {
        const int t = 2 * (y * (n - 1) + x) + k;
        std::swap(soup.triangles[t][1], soup.triangles[t][2]);
        std::swap(soup.corner_uv[t][1], soup.corner_uv[t][2]);
        ++flipped;
      }

  auto m = mesh_from_soup(soup, "defects.obj");
  ASSERT_TRUE(m.is_ok()) << m.status().message();
  const MeshRepairReport& r = m->repair;
  EXPECT_EQ(r.duplicate_faces, 2);
  EXPECT_EQ(r.non_manifold_edges, 1);
  EXPECT_EQ(r.non_manifold_faces, 1);
  EXPECT_EQ(r.flipped_faces, flipped);
  EXPECT_EQ(r.degenerate_faces, 2);
  EXPECT_EQ(r.non_finite_faces, 2);
  EXPECT_EQ(r.components, 2);
  EXPECT_EQ(r.removed_component_faces, 2);
  EXPECT_GT(r.kept_area_share, 0.9);
  std::printf("repair: %s\n", r.summary().c_str());
  // What is left is the grid: one disk, every face, all agreeing with the unflipped winding.
  EXPECT_EQ(m->mesh.n_faces(), grid_faces);
  EXPECT_EQ(m->mesh.n_vertices(), static_cast<size_t>(n * n));
  const MeshTopology t = mesh_topology(m->mesh);
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.boundary_loops, 1);
  EXPECT_EQ(t.genus, 0);
  for (auto f : m->mesh.faces()) EXPECT_GT(m->mesh.calc_face_normal(f)[2], 0.0);
  // The texture follows each face, flipped ones included: a corner's u is its point's x / 7.
  ASSERT_EQ(m->texture.face_image.size(), m->mesh.n_faces());
  for (auto f : m->mesh.faces()) {
    ASSERT_EQ(m->texture.face_image[f.idx()], 0);
    int k = 0;
    for (auto v : m->mesh.fv_range(f))
      EXPECT_NEAR(m->texture.face_uv[f.idx()][k++][0], m->mesh.point(v)[0] / (n - 1), 1e-6);
  }
}

TEST(MeshFromSoup, ThePairOfAFinIsTheEmbeddedOne) {
  // Two grid triangles share edge 0-4 of a 3 x 3 grid diagonal; a fin on it is dropped whichever
  // order the faces come in.
  for (bool fin_first : {false, true}) {
    TriangleSoup soup = grid_soup(3);
    soup.points.emplace_back(0.5, 0.5, 3.0);
    std::vector<std::array<int, 3>> triangles = soup.triangles;
    const std::array<int, 3> fin{0, 4, 9};
    if (fin_first)
      triangles.insert(triangles.begin(), fin);
    else
      triangles.push_back(fin);
    std::vector<char> drop(triangles.size(), 0);
    const FinReport report = drop_non_manifold_fins(triangles, &drop);
    EXPECT_EQ(report.non_manifold_edges, 1);
    EXPECT_EQ(report.dropped_faces, 1);
    const size_t fin_index = fin_first ? 0 : triangles.size() - 1;
    EXPECT_TRUE(drop[fin_index]);
  }
}

TEST(MeshFromSoup, NotOneSurfaceOrNothingLeftIsRefusedNamingTheFile) {
  // Three equal pieces: the largest holds a third of the area.
  TriangleSoup soup = grid_soup(4);
  for (int piece = 1; piece < 3; ++piece) {
    const int base = static_cast<int>(soup.points.size());
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) soup.points.emplace_back(100 * piece + x, y, 0.0);
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 3; ++x) {
        const int a = base + y * 4 + x;
        add_triangle(&soup, {a, a + 1, a + 5});
        add_triangle(&soup, {a, a + 5, a + 4});
      }
  }
  auto m = mesh_from_soup(soup, "thirds.ply");
  ASSERT_FALSE(m.is_ok());
  EXPECT_TRUE(contains(m.status().message(), "thirds.ply: the largest of 3 pieces holds only 33%"))
      << m.status().message();
  SoupMeshOptions one_piece;
  one_piece.keep_largest_piece = false;
  m = mesh_from_soup(soup, "thirds.ply", one_piece);
  ASSERT_FALSE(m.is_ok());
  EXPECT_TRUE(contains(m.status().message(), "thirds.ply: the mesh is in 3 pieces"))
      << m.status().message();

  TriangleSoup nan_only;
  nan_only.points = {{NAN, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  nan_only.triangles = {{0, 1, 2}};
  m = mesh_from_soup(nan_only, "nan.obj");
  ASSERT_FALSE(m.is_ok());
  EXPECT_TRUE(contains(m.status().message(), "nan.obj: no face is left after the repair"))
      << m.status().message();
}

}  // namespace
}  // namespace gvkit::facemap
