#include "gvkit/facemap/harmonic_field.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "gvkit/facemap/flow_coordinates.hpp"

namespace gvkit::facemap {
namespace {

// A planar ring 1 <= r <= 3, rings x sectors vertices, triangles counter-clockwise.
FaceAnnulus ring(int rings, int sectors) {
  FaceAnnulus a;
  TriSurface& s = a.surface;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < sectors; ++j) {
      const double r = 1.0 + 2.0 * i / (rings - 1), phi = 2 * M_PI * j / sectors;
      s.xyz.emplace_back(r * std::cos(phi), r * std::sin(phi), 0.0);
      s.source.push_back({{static_cast<int>(s.xyz.size()) - 1, 1.0}});
      s.uncut_vertex.push_back(static_cast<int>(s.xyz.size()) - 1);
    }
  auto id = [&](int i, int j) { return i * sectors + (j % sectors); };
  for (int i = 0; i + 1 < rings; ++i)
    for (int j = 0; j < sectors; ++j) {
      s.triangles.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      s.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
    }
  for (const auto& loop : tri_surface_boundary_loops(s)) {
    if (s.xyz[loop[0]].norm() < 2)
      a.inner_loop = loop;
    else
      a.outer_loop = loop;
  }
  return a;
}

TEST(HarmonicField, DirichletOnARingIsTheLogarithm) {
  const FaceAnnulus a = ring(17, 96);
  ASSERT_EQ(a.inner_loop.size(), 96u);
  ASSERT_EQ(a.outer_loop.size(), 96u);
  auto flow = flow_coordinates(a);
  ASSERT_TRUE(flow.is_ok()) << flow.status().message();
  // Boundary values exact, maximum principle, no interior extrema.
  for (int v : a.inner_loop) EXPECT_EQ(flow->t[v], 1.0);
  for (int v : a.outer_loop) EXPECT_EQ(flow->t[v], 0.0);
  EXPECT_EQ(flow->field_report.interior_extrema, 0);
  EXPECT_GT(flow->field_report.min_free, 0.0);
  EXPECT_LT(flow->field_report.max_free, 1.0);
  EXPECT_LT(flow->field_report.residual, 1e-9);
  // f = log(3 / r) / log 3 on the exact ring.
  double worst = 0;
  for (int v = 0; v < a.surface.n_vertices(); ++v) {
    const double r = a.surface.xyz[v].norm();
    worst = std::max(worst, std::abs(flow->t[v] - std::log(3.0 / r) / std::log(3.0)));
  }
  EXPECT_LT(worst, 0.01);
}

// One elimination order of the whole Laplacian, restricted to each system's free vertices,
// gives the solutions of each system ordered on its own (the reference), for f and for psi.
TEST(HarmonicField, OneEliminationOrderGivesTheReferenceSolutions) {
  const FaceAnnulus a = ring(9, 40);
  const int n = a.surface.n_vertices();
  const auto laplacian = cotan_laplacian(a.surface);
  const std::vector<int> order = laplacian_elimination_order(laplacian);
  ASSERT_EQ(static_cast<int>(order.size()), n);
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (int v = 0; v < n; ++v) ASSERT_EQ(sorted[v], v);  // a permutation
  std::vector<char> fixed(n, 0);
  std::vector<double> value(n, 0.0);
  for (int v : a.outer_loop) fixed[v] = 1;
  for (int v : a.inner_loop) fixed[v] = 1, value[v] = 1.0;
  auto ordered = solve_dirichlet(laplacian, fixed, value, order);
  auto reference = solve_dirichlet(laplacian, fixed, value);
  ASSERT_TRUE(ordered.is_ok() && reference.is_ok());
  for (int v = 0; v < n; ++v) EXPECT_NEAR((*ordered)[v], (*reference)[v], 1e-12) << v;
  auto psi_ordered = harmonic_conjugate(a.surface, laplacian, a.inner_loop, a.outer_loop, order);
  auto psi_reference = harmonic_conjugate(a.surface, laplacian, a.inner_loop, a.outer_loop);
  ASSERT_TRUE(psi_ordered.is_ok() && psi_reference.is_ok());
  for (size_t c = 0; c < psi_ordered->size(); ++c)
    EXPECT_NEAR((*psi_ordered)[c], (*psi_reference)[c], 1e-10) << c;
}

TEST(HarmonicField, ConjugateLevelSetsAreTheRadialIntegralCurves) {
  const FaceAnnulus a = ring(9, 64);
  auto flow = flow_coordinates(a);
  ASSERT_TRUE(flow.is_ok()) << flow.status().message();
  EXPECT_EQ(flow->flipped, 0);
  EXPECT_EQ(flow->boundary_nonmonotone, 0);
  // The gradient of f is radial, so s is constant along each ray (same sector index).
  const TriSurface& s = a.surface;
  std::vector<double> vertex_s(s.n_vertices(), NAN);
  for (int k = 0; k < s.n_triangles(); ++k)
    for (int j = 0; j < 3; ++j) {
      double x = flow->corner_s[3 * k + j];
      vertex_s[s.triangles[k][j]] = x - std::floor(x);
    }
  double worst = 0;
  for (int v = 64; v < s.n_vertices(); ++v) {
    double d = std::abs(vertex_s[v] - vertex_s[v % 64]);
    worst = std::max(worst, std::min(d, 1.0 - d));
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(HarmonicField, UntanglingRemovesFlipsAcrossTheSeam) {
  const FaceAnnulus a = ring(9, 64);
  auto flow = flow_coordinates(a);
  ASSERT_TRUE(flow.is_ok()) << flow.status().message();
  ASSERT_EQ(flow->flipped, 0);
  EXPECT_EQ(flow->untangled_vertices, 0);
  const TriSurface& s = a.surface;
  std::vector<char> fixed(s.n_vertices(), 0);
  for (int v : a.inner_loop) fixed[v] = 1;
  for (int v : a.outer_loop) fixed[v] = 1;
  // Two interior vertices pushed three sectors sideways and two rings outward: one on the
  // conjugate's seam (the ray through inner_loop[0], where corners differ by a period), one
  // half way round.
  std::vector<double> t = flow->t, corner_s = flow->corner_s;
  for (int v : {4 * 64 + a.inner_loop[0] % 64, 3 * 64 + (a.inner_loop[0] + 32) % 64}) {
    for (int k = 0; k < s.n_triangles(); ++k)
      for (int j = 0; j < 3; ++j)
        if (s.triangles[k][j] == v) corner_s[3 * k + j] += 3.0 / 64;
    t[v] = t[v + 2 * 64];
  }
  ASSERT_GT(count_flipped(s, t, corner_s), 4);
  const int moved = untangle_flow_coordinates(s, fixed, &t, &corner_s);
  EXPECT_GT(moved, 1);
  EXPECT_EQ(count_flipped(s, t, corner_s), 0);
  for (int v = 0; v < s.n_vertices(); ++v)
    if (fixed[v]) {
      EXPECT_EQ(t[v], flow->t[v]);
    }
  // Within each triangle the corners' s stay within a fraction of a period of each other.
  for (int k = 0; k < s.n_triangles(); ++k)
    for (int j = 1; j < 3; ++j) EXPECT_LT(std::abs(corner_s[3 * k + j] - corner_s[3 * k]), 0.2);
}

TEST(HarmonicField, SolveDirichletRejectsNothingFreeAndKeepsFixedValues) {
  const FaceAnnulus a = ring(3, 8);
  const auto l = cotan_laplacian(a.surface);
  std::vector<char> fixed(a.surface.n_vertices(), 1);
  std::vector<double> value(a.surface.n_vertices(), 0.25);
  auto f = solve_dirichlet(l, fixed, value);
  ASSERT_TRUE(f.is_ok());
  for (double x : *f) EXPECT_EQ(x, 0.25);
}

}  // namespace
}  // namespace gvkit::facemap
