#include "gvkit/facemap/multigrid_solver.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/SparseCholesky>

#include "gvkit/facemap/flow_coordinates.hpp"
#include "gvkit/facemap/harmonic_field.hpp"
#include "ring_annulus.hpp"

namespace gvkit::facemap {
namespace {

// A planar ring 1 <= r <= 3 of rings x sectors vertices, the interior ones jittered (so the cotan
// weights vary and some edges are not Delaunay), triangles counter-clockwise.
FaceAnnulus jittered_ring(int rings, int sectors, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  return testing::ring_annulus(rings, sectors, [&](int i, int j) {
    const bool interior = i > 0 && i + 1 < rings;
    const double r = 1.0 + 2.0 * (i + (interior ? jitter(rng) : 0.0)) / (rings - 1);
    const double phi = 2 * M_PI * (j + (interior ? jitter(rng) : 0.0)) / sectors;
    return Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), 0.05 * std::sin(3 * phi) * r);
  });
}

// The reduced Dirichlet system of f on the ring: the free vertices' rows and columns.
Eigen::SparseMatrix<double> dirichlet_system(const FaceAnnulus& a) {
  const auto laplacian = cotan_laplacian(a.surface, kDefaultMinCotanWeight);
  const int n = a.surface.n_vertices();
  std::vector<int> index(n, 0);
  for (int v : a.inner_loop) index[v] = -1;
  for (int v : a.outer_loop) index[v] = -1;
  int m = 0;
  for (int& i : index)
    if (i == 0) i = m++;
  std::vector<Eigen::Triplet<double>> entries;
  for (int col = 0; col < n; ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian, col); it; ++it)
      if (index[col] >= 0 && index[it.row()] >= 0)
        entries.emplace_back(index[it.row()], index[col], it.value());
  Eigen::SparseMatrix<double> a_free(m, m);
  a_free.setFromTriplets(entries.begin(), entries.end());
  return a_free;
}

TEST(MultigridSolver, MatchesTheDirectSolveOnAJitteredRing) {
  const Eigen::SparseMatrix<double> a = dirichlet_system(jittered_ring(50, 160, 1));
  ASSERT_GT(a.rows(), 7000);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> uniform(-1, 1);
  Eigen::VectorXd b(a.rows());
  for (int i = 0; i < b.size(); ++i) b[i] = uniform(rng);
  const Eigen::VectorXd reference = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(a).solve(b);
  MultigridOptions options;
  options.coarsest_size = 200;  // several levels on this small system
  MultigridSolver solver(options);
  ASSERT_TRUE(solver.compute(a).is_ok());
  EXPECT_GE(solver.levels(), 3);
  Eigen::VectorXd x;
  const Status status = solver.solve(b, &x);
  ASSERT_TRUE(status.is_ok()) << status.message();
  EXPECT_LE(solver.residual(), options.tolerance);
  EXPECT_LT(solver.iterations(), 60);
  EXPECT_LT((x - reference).cwiseAbs().maxCoeff(), 1e-8 * reference.cwiseAbs().maxCoeff());
  // A second solve from the answer stops at once.
  ASSERT_TRUE(solver.solve(b, &x).is_ok());
  EXPECT_EQ(solver.iterations(), 0);
}

// f and psi, and so the flow coordinates, by multigrid are the direct solver's within a
// tolerance (t in [0, 1], s in [0, 1) per period; at the solver's relative residual of 1e-8 the
// difference on this ring is about 1e-8, far below a geometry image's float precision).
TEST(MultigridSolver, FlowCoordinatesMatchTheDirectSolves) {
  const FaceAnnulus a = jittered_ring(40, 150, 3);
  auto direct = flow_coordinates(a, {}, RimCorrespondence::kFlow, kDefaultMinCotanWeight,
                                 HarmonicSolver::kDirect);
  auto multigrid = flow_coordinates(a, {}, RimCorrespondence::kFlow, kDefaultMinCotanWeight,
                                    HarmonicSolver::kMultigrid);
  ASSERT_TRUE(direct.is_ok()) << direct.status().message();
  ASSERT_TRUE(multigrid.is_ok()) << multigrid.status().message();
  EXPECT_EQ(direct->solver, HarmonicSolver::kDirect);
  EXPECT_EQ(multigrid->solver, HarmonicSolver::kMultigrid);
  double worst_t = 0, worst_s = 0;
  for (size_t v = 0; v < direct->t.size(); ++v)
    worst_t = std::max(worst_t, std::abs(direct->t[v] - multigrid->t[v]));
  for (size_t c = 0; c < direct->corner_s.size(); ++c)
    worst_s = std::max(worst_s, std::abs(direct->corner_s[c] - multigrid->corner_s[c]));
  EXPECT_LT(worst_t, 1e-7);
  EXPECT_LT(worst_s, 1e-6);
  EXPECT_EQ(multigrid->flipped, direct->flipped);
  EXPECT_EQ(multigrid->field_report.interior_extrema, direct->field_report.interior_extrema);
  // kAuto keeps small systems on the direct solver.
  EXPECT_EQ(resolve_harmonic_solver(HarmonicSolver::kAuto, 6000), HarmonicSolver::kDirect);
  EXPECT_EQ(resolve_harmonic_solver(HarmonicSolver::kAuto, kMultigridMinVertices),
            HarmonicSolver::kMultigrid);
}

TEST(MultigridSolver, RejectsBadOptionsAndMatrices) {
  MultigridOptions options;
  options.tolerance = 0;
  EXPECT_NE(options.check().message().find("tolerance"), std::string::npos);
  options = {};
  options.max_coarse_fraction = 1.5;
  EXPECT_NE(options.check().message().find("max_coarse_fraction"), std::string::npos);
  Eigen::SparseMatrix<double> a(3, 3);
  a.insert(0, 0) = 1;
  a.insert(1, 1) = 0;  // not positive
  a.insert(2, 2) = 1;
  MultigridSolver solver;
  const Status status = solver.compute(a);
  EXPECT_FALSE(status.is_ok());
  EXPECT_NE(status.message().find("diagonal entry 1"), std::string::npos) << status.message();
  // Through solve_dirichlet: a forced multigrid reports the reason with the system's name (kAuto
  // would factorize instead).
  Eigen::SparseMatrix<double> laplacian(3, 3);
  laplacian.insert(0, 0) = 1, laplacian.insert(0, 2) = -1;
  laplacian.insert(2, 0) = -1, laplacian.insert(2, 2) = 1;
  laplacian.insert(1, 1) = 0;  // a free vertex without edges
  const auto solved =
      solve_dirichlet(laplacian, {1, 0, 0}, {1.0, 0.0, 0.0}, {}, HarmonicSolver::kMultigrid);
  ASSERT_FALSE(solved.is_ok());
  EXPECT_NE(solved.status().message().find("harmonic field: multigrid: diagonal entry"),
            std::string::npos)
      << solved.status().message();
}

}  // namespace
}  // namespace gvkit::facemap
