// Heat-method geodesics against exact distances on a plane and a sphere.
#include "gvkit/facemap/geodesic_distance.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <utility>

#include <gtest/gtest.h>

#include "gvkit/facemap/fast_marching.hpp"
#include "gvkit/facemap/intrinsic_triangulation.hpp"

namespace gvkit::facemap {
namespace {

// n x n grid of spacing 1 mm in the z = 0 plane, jittered, optionally sheared (obtuse triangles).
Mesh plane_grid(int n, double jitter, double shear) {
  Mesh mesh;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  std::vector<Mesh::VertexHandle> v(n * n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const bool border = x == 0 || y == 0 || x == n - 1 || y == n - 1;
      const double jx = border ? 0.0 : u(rng), jy = border ? 0.0 : u(rng);
      v[y * n + x] = mesh.add_vertex(Mesh::Point(x + shear * y + jx, y + jy, 0.0));
    }
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      const auto a = v[y * n + x], b = v[y * n + x + 1], c = v[(y + 1) * n + x + 1],
                 d = v[(y + 1) * n + x];
      mesh.add_face(a, b, c);
      mesh.add_face(a, c, d);
    }
  return mesh;
}

// Icosphere of the given radius with `levels` midpoint subdivisions.
Mesh icosphere(double radius, int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& q : p) q.normalize();
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      p.push_back((p[a] + p[b]).normalized());
      return mid[key] = static_cast<int>(p.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (auto [a, b, c] : f) {
      const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.push_back({a, ab, ca});
      next.push_back({b, bc, ab});
      next.push_back({c, ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  Mesh mesh;
  std::vector<Mesh::VertexHandle> v;
  for (const auto& q : p)
    v.push_back(mesh.add_vertex(Mesh::Point(radius * q.x(), radius * q.y(), radius * q.z())));
  for (auto [a, b, c] : f) mesh.add_face(v[a], v[b], v[c]);
  return mesh;
}

struct Errors {
  double mean_relative = 0.0, max_relative = 0.0;
};
// Relative errors over vertices farther than min_distance from the source.
template <typename Exact>
Errors relative_errors(const Mesh& mesh, const std::vector<double>& d, Exact exact,
                       double min_distance) {
  Errors e;
  int n = 0;
  for (auto v : mesh.vertices()) {
    const double truth = exact(v);
    if (truth < min_distance) continue;
    const double rel = std::abs(d[v.idx()] - truth) / truth;
    e.mean_relative += rel;
    e.max_relative = std::max(e.max_relative, rel);
    ++n;
  }
  e.mean_relative /= n;
  std::printf("mean relative error %.4f, max %.4f\n", e.mean_relative, e.max_relative);
  return e;
}

TEST(GeodesicDistance, PlaneMatchesEuclideanDistance) {
  const int n = 41;
  const Mesh mesh = plane_grid(n, 0.2, 0.0);
  const auto source = mesh.vertex_handle((n / 2) * n + n / 2);
  const HeatGeodesics geodesics(mesh);
  const auto d = geodesics.distance({source});
  EXPECT_EQ(d[source.idx()], 0.0);
  const Errors e = relative_errors(
      mesh, d, [&](auto v) { return (mesh.point(v) - mesh.point(source)).norm(); }, 3.0);
  EXPECT_LT(e.mean_relative, 0.025);
  EXPECT_LT(e.max_relative, 0.08);
}

TEST(GeodesicDistance, SphereMatchesGreatCircleDistance) {
  const double radius = 50.0;
  const Mesh mesh = icosphere(radius, 4);  // 2562 vertices
  const auto source = mesh.vertex_handle(0);
  const Eigen::Vector3d s(mesh.point(source).data());
  const HeatGeodesics geodesics(mesh);
  const auto d = geodesics.distance({source});
  const Errors e = relative_errors(
      mesh, d,
      [&](auto v) {
        const Eigen::Vector3d q(mesh.point(v).data());
        return radius * std::acos(std::clamp(s.dot(q) / (radius * radius), -1.0, 1.0));
      },
      10.0);
  EXPECT_LT(e.mean_relative, 0.02);
  EXPECT_LT(e.max_relative, 0.10);
}

// Fast marching against the same exact distances, and against the heat method (its reference).
TEST(FastMarching, PlaneMatchesEuclideanDistance) {
  const int n = 41;
  const Mesh mesh = plane_grid(n, 0.2, 0.0);
  const auto source = mesh.vertex_handle((n / 2) * n + n / 2);
  const auto d = FastMarching(mesh).distance({source});
  EXPECT_EQ(d[source.idx()], 0.0);
  auto exact = [&](auto v) { return (mesh.point(v) - mesh.point(source)).norm(); };
  const Errors e = relative_errors(mesh, d, exact, 3.0);
  EXPECT_LT(e.mean_relative, 0.025);
  EXPECT_LT(e.max_relative, 0.08);
  const Errors heat = relative_errors(mesh, HeatGeodesics(mesh).distance({source}), exact, 3.0);
  EXPECT_LT(e.mean_relative, 2.0 * heat.mean_relative);
}

TEST(FastMarching, SphereMatchesGreatCircleDistance) {
  const double radius = 50.0;
  const Mesh mesh = icosphere(radius, 4);
  const auto source = mesh.vertex_handle(0);
  const Eigen::Vector3d s(mesh.point(source).data());
  const auto d = FastMarching(mesh).distance({source});
  const Errors e = relative_errors(
      mesh, d,
      [&](auto v) {
        const Eigen::Vector3d q(mesh.point(v).data());
        return radius * std::acos(std::clamp(s.dot(q) / (radius * radius), -1.0, 1.0));
      },
      10.0);
  EXPECT_LT(e.mean_relative, 0.02);
  EXPECT_LT(e.max_relative, 0.10);
}

TEST(FastMarching, StopsAtTheBoundWithTheSameDistancesInside) {
  const int n = 41;
  const Mesh mesh = plane_grid(n, 0.2, 0.0);
  const auto a = mesh.vertex_handle(10 * n + 10), b = mesh.vertex_handle(30 * n + 30);
  const FastMarching marching(mesh);
  const auto full = marching.distance({a, b});
  const auto bounded = marching.distance({a, b}, 5.0);
  int inside = 0;
  for (size_t i = 0; i < full.size(); ++i) {
    if (full[i] <= 5.0) {
      EXPECT_EQ(bounded[i], full[i]);
      ++inside;
    } else {
      EXPECT_TRUE(std::isinf(bounded[i]));
    }
  }
  EXPECT_GT(inside, 100);
  EXPECT_EQ(full[a.idx()], 0.0);
  EXPECT_EQ(full[b.idx()], 0.0);
  EXPECT_TRUE(FastMarching(mesh).distance({}).front() > 1e300);
}

// The heap with keys is an optimisation of the same computation: the same values to the bit, on
// jittered and sheared grids (ties and fallbacks), several sources, with and without a bound.
TEST(FastMarching, HeapWithKeysMatchesTheReference) {
  const Mesh flat = plane_grid(41, 0.0, 0.0);  // many exactly equal distances: the tie order
  const Mesh jittered = plane_grid(41, 0.3, 0.0);
  const Mesh sheared = plane_grid(41, 0.2, 2.0);
  const Mesh sphere = icosphere(30.0, 3);
  for (const Mesh* mesh : {&flat, &jittered, &sheared, &sphere}) {
    const FastMarching marching(*mesh);
    const int n = static_cast<int>(mesh->n_vertices());
    const std::vector<Mesh::VertexHandle> sources = {
        mesh->vertex_handle(n / 7), mesh->vertex_handle(n / 2), mesh->vertex_handle(n - 3)};
    for (const double bound : {std::numeric_limits<double>::infinity(), 6.0}) {
      const auto fast = marching.distance(sources, bound);
      const auto reference = marching.distance_reference(sources, bound);
      ASSERT_EQ(fast.size(), reference.size());
      for (size_t i = 0; i < fast.size(); ++i)
        ASSERT_EQ(fast[i], reference[i]) << "vertex " << i << ", bound " << bound;
    }
  }
}

// reached() gives the finite entries of distance() alone, to the bit, and its arrays reset
// between calls (a second query on the same object is not affected by the first).
TEST(FastMarching, ReachedGivesTheFiniteDistances) {
  const Mesh jittered = plane_grid(41, 0.3, 0.0);
  FastMarching marching(jittered);
  const int n = static_cast<int>(jittered.n_vertices());
  const std::vector<Mesh::VertexHandle> first = {jittered.vertex_handle(n / 3)},
                                        second = {jittered.vertex_handle(n / 2),
                                                  jittered.vertex_handle(n - 5)};
  for (const auto* sources : {&first, &second, &first}) {
    for (const double bound : {2.0, 5.0, std::numeric_limits<double>::infinity()}) {
      const auto full = marching.distance(*sources, bound);
      std::vector<double> sparse(n, std::numeric_limits<double>::infinity());
      const auto reached = marching.reached(*sources, bound);
      for (const auto& [v, d] : reached) {
        ASSERT_TRUE(v >= 0 && v < n);
        ASSERT_TRUE(std::isinf(sparse[v])) << "vertex " << v << " given twice";
        sparse[v] = d;
      }
      for (int i = 0; i < n; ++i) ASSERT_EQ(sparse[i], full[i]) << "vertex " << i;
      EXPECT_EQ(reached.size(), static_cast<size_t>(std::count_if(
                                    full.begin(), full.end(), [](double d) { return d < 1e300; })));
    }
  }
}

TEST(GeodesicDistance, MultipleSourcesGiveTheNearest) {
  const int n = 41;
  const Mesh mesh = plane_grid(n, 0.0, 0.0);
  const auto a = mesh.vertex_handle(10 * n + 10), b = mesh.vertex_handle(30 * n + 30);
  const HeatGeodesics geodesics(mesh);
  const auto d = geodesics.distance({a, b});
  EXPECT_EQ(d[a.idx()], 0.0);
  EXPECT_EQ(d[b.idx()], 0.0);
  const Errors e = relative_errors(
      mesh, d,
      [&](auto v) {
        return std::min((mesh.point(v) - mesh.point(a)).norm(),
                        (mesh.point(v) - mesh.point(b)).norm());
      },
      3.0);
  EXPECT_LT(e.mean_relative, 0.03);
}

TEST(GeodesicDistance, CholmodMatchesReferenceSolver) {
  const Mesh mesh = icosphere(20.0, 3);
  HeatGeodesicsOptions reference;
  reference.solver = SparseSolverKind::kSimplicialLdlt;
  const auto d_fast = HeatGeodesics(mesh).distance({mesh.vertex_handle(5)});
  const auto d_ref = HeatGeodesics(mesh, reference).distance({mesh.vertex_handle(5)});
  ASSERT_EQ(d_fast.size(), d_ref.size());
  for (size_t i = 0; i < d_fast.size(); ++i) EXPECT_NEAR(d_fast[i], d_ref[i], 1e-6);
}

TEST(GeodesicDistance, IntrinsicDelaunayHelpsOnObtuseTriangles) {
  const int n = 41;
  const Mesh mesh = plane_grid(n, 0.0, 2.5);  // strongly sheared: obtuse angles everywhere
  const auto source = mesh.vertex_handle((n / 2) * n + n / 2);
  auto exact = [&](auto v) { return (mesh.point(v) - mesh.point(source)).norm(); };
  HeatGeodesicsOptions plain;
  plain.intrinsic_delaunay = false;
  const HeatGeodesics delaunay(mesh);
  EXPECT_GT(delaunay.intrinsic_flips(), 0);
  const Errors e_plain =
      relative_errors(mesh, HeatGeodesics(mesh, plain).distance({source}), exact, 3.0);
  const Errors e_delaunay = relative_errors(mesh, delaunay.distance({source}), exact, 3.0);
  EXPECT_LT(e_delaunay.mean_relative, e_plain.mean_relative);
  EXPECT_LT(e_delaunay.mean_relative, 0.05);

  // After the flips every cotan weight is non-negative.
  IntrinsicTriangulation tri(mesh);
  tri.flip_to_delaunay();
  std::vector<Eigen::Triplet<double>> l;
  tri.cotan_laplacian(&l);
  Eigen::SparseMatrix<double> laplacian(mesh.n_vertices(), mesh.n_vertices());
  laplacian.setFromTriplets(l.begin(), l.end());
  for (int k = 0; k < laplacian.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian, k); it; ++it) {
      if (it.row() != it.col() && !(tri.mesh().is_boundary(tri.mesh().vertex_handle(it.row())) &&
                                    tri.mesh().is_boundary(tri.mesh().vertex_handle(it.col())))) {
        EXPECT_LE(it.value(), 1e-9);  // interior edges; boundary edges cannot be flipped
      }
    }
}

TEST(GeodesicDistance, ComponentWithoutSourceIsInfinite) {
  Mesh mesh = plane_grid(21, 0.0, 0.0);
  const auto a = mesh.add_vertex(Mesh::Point(100, 0, 0));
  const auto b = mesh.add_vertex(Mesh::Point(101, 0, 0));
  const auto c = mesh.add_vertex(Mesh::Point(100, 1, 0));
  mesh.add_face(a, b, c);
  const auto d = HeatGeodesics(mesh).distance({mesh.vertex_handle(0)});
  EXPECT_TRUE(std::isinf(d[a.idx()]));
  EXPECT_NEAR(d[10 * 21 + 10], std::hypot(10.0, 10.0), 0.5);
}

TEST(GeodesicDistance, OptionsAreChecked) {
  HeatGeodesicsOptions options;
  EXPECT_TRUE(options.check().is_ok());
  options.time_factor = 0.0;
  EXPECT_FALSE(options.check().is_ok());
  EXPECT_NE(options.check().message().find("time_factor"), std::string::npos);
}

}  // namespace
}  // namespace gvkit::facemap
