#include "gvkit/facemap/harmonic_field.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <utility>

#include "gvkit/facemap/flow_coordinates.hpp"
#include "ring_annulus.hpp"

namespace gvkit::facemap {
namespace {

constexpr double kPlainWeights = -std::numeric_limits<double>::infinity();

// A planar ring 1 <= r <= 3, rings x sectors vertices, triangles counter-clockwise.
FaceAnnulus ring(int rings, int sectors) { return testing::ring_annulus(rings, sectors); }

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

// With the plain weights (linear precision) s is exactly constant along each ray. The floor
// raises the weights of the trapezoids' diagonals (about 0: their opposite angles are 87 and 93
// degrees), all leaning one way, which turns the curves a little; it stays within a tenth of a
// sector.
TEST(HarmonicField, ConjugateLevelSetsAreTheRadialIntegralCurves) {
  for (double floor : {kPlainWeights, kDefaultMinCotanWeight}) {
    const FaceAnnulus a = ring(9, 64);
    auto flow = flow_coordinates(a, {}, RimCorrespondence::kAngle, floor);
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
    EXPECT_LT(worst, floor < 0 ? 1e-6 : 0.1 / 64) << floor;
  }
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

// A whole ray of interior vertices pushed one and a half sectors sideways: a strip of flipped
// triangles from the inner to the outer boundary, which the untangling removes, keeping the
// boundaries where they were.
TEST(HarmonicField, UntanglingRemovesAStripOfFlipsAcrossTheRing) {
  const FaceAnnulus a = ring(14, 64);
  auto flow = flow_coordinates(a);
  ASSERT_TRUE(flow.is_ok()) << flow.status().message();
  const TriSurface& s = a.surface;
  std::vector<char> fixed(s.n_vertices(), 0);
  for (int v : a.inner_loop) fixed[v] = 1;
  for (int v : a.outer_loop) fixed[v] = 1;
  std::vector<double> t = flow->t, corner_s = flow->corner_s;
  const int sector = (a.inner_loop[0] + 20) % 64;
  for (int ring_index = 1; ring_index + 1 < 14; ++ring_index) {
    const int v = ring_index * 64 + sector;
    for (int k = 0; k < s.n_triangles(); ++k)
      for (int j = 0; j < 3; ++j)
        if (s.triangles[k][j] == v) corner_s[3 * k + j] += 1.5 / 64;
  }
  ASSERT_GT(count_flipped(s, t, corner_s), 12);
  EXPECT_GE(untangle_flow_coordinates(s, fixed, &t, &corner_s), 12);
  EXPECT_EQ(count_flipped(s, t, corner_s), 0);
  for (int v = 0; v < s.n_vertices(); ++v)
    if (fixed[v]) {
      EXPECT_EQ(t[v], flow->t[v]);
    }
}

// A ring whose interior vertices are pushed sideways by up to `jitter` of a sector and up and
// down by up to `jitter` of a ring spacing (a fixed pseudo-random pattern), every other ring
// shifted by half a sector: many triangles are obtuse, some strongly, as on a noisy scan.
FaceAnnulus jittered_ring(int rings, int sectors, double jitter) {
  FaceAnnulus a = ring(rings, sectors);
  std::mt19937 engine(12345);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  auto random = [&] { return uniform(engine); };
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < sectors; ++j) {
      Eigen::Vector3d& p = a.surface.xyz[i * sectors + j];
      const double r = p.norm(), step = 2 * M_PI / sectors;
      const double phi = std::atan2(p.y(), p.x()) + step * (0.5 * (i % 2) + jitter * random());
      const double dr = 2.0 / (rings - 1) * 0.45 * jitter * random();
      const double dz = 2.0 / (rings - 1) * jitter * random();  // like depth noise
      p = Eigen::Vector3d((r + dr) * std::cos(phi), (r + dr) * std::sin(phi), dz);
    }
  return a;
}

// A vertex whose edge to w is opposite two nearly flat angles (170 degrees) has a strongly
// negative cotangent weight to w: with w at 0 and the rest of its ring at 1, the plain solution
// overshoots 1 (an interior maximum); the floored weights keep it inside (0, 1).
TEST(HarmonicField, FlooredCotangentsKeepTheMaximumPrinciple) {
  TriSurface s;
  for (const auto& p :
       {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.5, 0.04, 0),
        Eigen::Vector3d(-1, 1, 0), Eigen::Vector3d(-1, -1, 0), Eigen::Vector3d(0.5, -0.04, 0)})
    s.xyz.push_back(p);
  s.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}, {0, 5, 1}};
  std::vector<char> fixed = {0, 1, 1, 1, 1, 1};
  const std::vector<double> value = {0, 0, 1, 1, 1, 1};
  const auto plain_l = cotan_laplacian(s, kPlainWeights);
  ASSERT_GT(plain_l.coeff(0, 1), 0.0) << "the weight of edge 0-1 should be negative";
  auto plain = solve_dirichlet(plain_l, fixed, value);
  ASSERT_TRUE(plain.is_ok());
  EXPECT_GT((*plain)[0], 1.0);
  EXPECT_EQ(check_harmonic_field(s, plain_l, fixed, *plain).interior_extrema, 1);
  const auto floored_l = cotan_laplacian(s, kDefaultMinCotanWeight);
  for (int k = 0; k < floored_l.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(floored_l, k); it; ++it)
      if (it.row() != it.col()) {
        EXPECT_LT(it.value(), 0.0);  // every weight positive
      }
  auto floored = solve_dirichlet(floored_l, fixed, value);
  ASSERT_TRUE(floored.is_ok());
  EXPECT_GT((*floored)[0], 0.0);
  EXPECT_LT((*floored)[0], 1.0);
  EXPECT_EQ(check_harmonic_field(s, floored_l, fixed, *floored).interior_extrema, 0);
}

// On a ring with many obtuse triangles the plain weights give (s, t) flips that the untangling
// has to remove; the floored weights give a flip-free (s, t) as solved.
TEST(HarmonicField, FlooredCotangentsGiveFlipFreeFlowCoordinates) {
  const FaceAnnulus a = jittered_ring(12, 48, 0.9);
  auto plain = flow_coordinates(a, {}, RimCorrespondence::kFlow, kPlainWeights);
  auto floored = flow_coordinates(a, {}, RimCorrespondence::kFlow);
  ASSERT_TRUE(plain.is_ok() && floored.is_ok());
  EXPECT_EQ(floored->min_cotan_weight, kDefaultMinCotanWeight);
  EXPECT_GT(plain->untangled_vertices, 0);
  EXPECT_EQ(floored->untangled_vertices, 0);
  EXPECT_EQ(floored->flipped, 0);
  EXPECT_EQ(floored->field_report.interior_extrema, 0);
  EXPECT_EQ(floored->boundary_nonmonotone, 0);
}

// The conjugate's jump enters through the Laplacian's own edge weights, whatever the floor: at
// every vertex off the seam psi is the weighted mean of its neighbours' values in the triangles
// around it (boundaries included: zero normal derivative), so it is harmonic for that Laplacian.
TEST(HarmonicField, ConjugateIsHarmonicForTheLaplacianItIsGiven) {
  const FaceAnnulus a = jittered_ring(10, 40, 0.9);
  const TriSurface& s = a.surface;
  for (double floor : {kPlainWeights, 0.0, kDefaultMinCotanWeight, 0.3}) {
    const auto l = cotan_laplacian(s, floor);
    auto psi = harmonic_conjugate(s, l, a.inner_loop, a.outer_loop);
    ASSERT_TRUE(psi.is_ok()) << floor << ": " << psi.status().message();
    // Per vertex: its value when all its corners agree (off the seam), NaN on the seam.
    std::vector<double> value(s.n_vertices(), NAN);
    std::vector<char> seen(s.n_vertices(), 0), on_seam(s.n_vertices(), 0);
    for (int k = 0; k < s.n_triangles(); ++k)
      for (int j = 0; j < 3; ++j) {
        const int v = s.triangles[k][j];
        const double x = (*psi)[3 * k + j];
        if (!seen[v]) seen[v] = 1, value[v] = x;
        if (std::abs(x - value[v]) > 1e-9) on_seam[v] = 1;
      }
    // Weighted sum of (psi_w - psi_v) over the edges at v, psi_w read in a triangle with v;
    // each edge is seen from each of its triangles (two for an interior edge, one on a boundary).
    std::map<std::pair<int, int>, int> triangles_of_edge;
    for (const auto& t : s.triangles)
      for (int j = 0; j < 3; ++j) ++triangles_of_edge[std::minmax(t[j], t[(j + 1) % 3])];
    std::vector<double> residual(s.n_vertices(), 0.0);
    for (int k = 0; k < s.n_triangles(); ++k)
      for (int j = 0; j < 3; ++j)
        for (int m = 1; m < 3; ++m) {
          const int v = s.triangles[k][j], w = s.triangles[k][(j + m) % 3];
          residual[v] += -l.coeff(v, w) * ((*psi)[3 * k + (j + m) % 3] - (*psi)[3 * k + j]) /
                         triangles_of_edge.at(std::minmax(v, w));
        }
    int checked = 0;
    for (int v = 0; v < s.n_vertices(); ++v) {
      if (on_seam[v] || v == a.inner_loop[0]) continue;  // the seam, and the pinned vertex
      EXPECT_NEAR(residual[v], 0.0, 1e-9) << "floor " << floor << ", vertex " << v;
      ++checked;
    }
    EXPECT_GT(checked, s.n_vertices() * 8 / 10);
  }
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
