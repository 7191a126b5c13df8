#pragma once
// Harmonic fields on a TriSurface with the cotangent Laplacian: the Dirichlet problem (f = 0 on
// one boundary, 1 on another: step 5 of the seed's Algorithm 1) and the harmonic conjugate of
// such an f on an annulus, whose level sets are the integral curves of grad f.

#include <limits>
#include <vector>

#include <Eigen/SparseCore>

#include "gvkit/core/status.hpp"
#include "gvkit/facemap/tri_surface.hpp"

namespace gvkit::facemap {

// Cotangent stiffness matrix L (symmetric positive semi-definite: L_ij = -w_ij, L_ii = sum w_ij,
// w_ij = (cot alpha + cot beta) / 2, dimensionless). min_cotan_weight: every edge weight is raised
// to at least this; -infinity keeps the plain weights. A plain weight is negative exactly where
// the edge is not locally Delaunay (alpha + beta > 180 degrees), so a small positive floor
// changes only those edges and makes L an M-matrix: a Dirichlet solution has no interior
// extrema (discrete maximum principle) and every free value is a convex combination of its
// neighbours' (Tutte), at the price of linear precision on the edges it raises.
Eigen::SparseMatrix<double> cotan_laplacian(
    const TriSurface& surface, double min_cotan_weight = -std::numeric_limits<double>::infinity());

// A fill-reducing elimination order of all the vertices of L (AMD on its pattern; order[k] is the
// vertex eliminated k-th). The systems below are L restricted to their free vertices, and this
// order restricted to a subset of the vertices fills no more there than on the whole, so one
// order serves every system of one surface instead of an AMD ordering per system.
std::vector<int> laplacian_elimination_order(const Eigen::SparseMatrix<double>& laplacian);

// How the systems below are solved. kDirect: a sparse LDL' factorization (the reference).
// kMultigrid: conjugate gradients with an algebraic multigrid preconditioner (MultigridSolver,
// relative residual 1e-8), about linear in the number of unknowns: faster from about 25K
// vertices on (10K-vertex ICT faces: 27 against 20 ms for f and psi; 43K-vertex main-job faces:
// 108 against 149 ms with the shared order). kAuto: kMultigrid from kMultigridMinVertices free
// vertices on, else kDirect; when the multigrid iteration fails (does not converge) kAuto
// factorizes instead, kMultigrid fails.
enum class HarmonicSolver { kAuto, kDirect, kMultigrid };
inline constexpr int kMultigridMinVertices = 30000;
// The solver kAuto picks for a system of n_free unknowns (others are returned as given).
HarmonicSolver resolve_harmonic_solver(HarmonicSolver solver, int n_free);

// Solves L f = 0 at free vertices with f = value at the fixed ones (fixed[i] >= 0 marks vertex
// i fixed to value[i]). order: laplacian_elimination_order(laplacian), or empty to order the
// reduced system on its own (the reference; same solution up to round-off); the direct solver's
// only. Fails when the factorization fails (a singular system) or the multigrid iteration does
// not converge.
Result<std::vector<double>> solve_dirichlet(const Eigen::SparseMatrix<double>& laplacian,
                                            const std::vector<char>& fixed,
                                            const std::vector<double>& value,
                                            const std::vector<int>& order = {},
                                            HarmonicSolver solver = HarmonicSolver::kDirect);

// How well a discrete harmonic field keeps the maximum principle.
struct HarmonicFieldReport {
  int interior_extrema = 0;  // free vertices that are a strict local min or max among neighbours
  double min_free = 0, max_free = 0;  // range over free vertices (inside [0, 1] when it holds)
  double residual = 0;                // max |L f| over free vertices
};
HarmonicFieldReport check_harmonic_field(const TriSurface& surface,
                                         const Eigen::SparseMatrix<double>& laplacian,
                                         const std::vector<char>& fixed,
                                         const std::vector<double>& f);

// The harmonic conjugate of the Dirichlet field f (0 outer, 1 inner) on an annulus, up to scale, as
// per-corner values psi (triangle k, corner j at [3k + j]): psi is harmonic with zero normal
// derivative on both boundaries and jumps by 1 across a seam from inner_loop[0] to the outer
// boundary, so it is single-valued per triangle. Its values increase by exactly 1 around inner_loop
// in loop order. laplacian: any symmetric Laplacian with weights on the surface's edges (e.g.
// cotan_laplacian with any floor); the seam's jump enters through those same weights. order,
// solver: as for solve_dirichlet.
Result<std::vector<double>> harmonic_conjugate(const TriSurface& surface,
                                               const Eigen::SparseMatrix<double>& laplacian,
                                               const std::vector<int>& inner_loop,
                                               const std::vector<int>& outer_loop,
                                               const std::vector<int>& order = {},
                                               HarmonicSolver solver = HarmonicSolver::kDirect);

}  // namespace gvkit::facemap
