#pragma once
// An iterative solver for the sparse symmetric positive definite systems of the map stage (the
// Dirichlet problems of harmonic_field.hpp on large meshes): conjugate gradients preconditioned
// with one V-cycle of smoothed-aggregation algebraic multigrid. The coarse levels are built from
// the matrix alone (aggregates of strongly connected unknowns, prolongation smoothed by one
// damped Jacobi step, Galerkin coarse matrices), so any triangle mesh works; the coarsest level
// is factorized. A direct factorization's cost grows faster than the number of unknowns (fill);
// this one's grows about linearly, so it wins on large meshes (docs/benchmarks.md, "facemap per
// frame at 250K vertices"). The solution matches a direct solve to the given tolerance.

#include <memory>
#include <vector>

#include <Eigen/SparseCore>

#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

struct MultigridOptions {
  // An off-diagonal entry is a strong connection when |a_ij| >= threshold * sqrt(a_ii a_jj);
  // aggregates follow strong connections only.
  double strength_threshold = 0.08;
  int coarsest_size = 1500;  // unknowns at which the hierarchy stops and factorizes
  // A level whose aggregates would keep more than this fraction of its unknowns is the coarsest
  // (coarsening has stalled).
  double max_coarse_fraction = 0.5;
  int sweeps = 1;  // Gauss-Seidel sweeps before (forward) and after (backward) the coarse step
  // The matrix is singular with the constants as its null space (a Laplacian with nothing fixed,
  // b summing to 0): the coarsest level is solved with its last unknown fixed at 0 and the
  // constant part of every preconditioned residual is removed; the solution is then one of the
  // solutions, up to an added constant.
  bool constant_null_space = false;
  int max_levels = 16;
  // Stop when |b - A x| <= tolerance * |b| (Euclidean norms). At 1e-8 the map's f and psi on a
  // 250K-vertex face are within about 2e-11 of their largest value of the direct solution.
  double tolerance = 1e-8;
  int max_iterations = 300;
  Status check() const;
};

class MultigridSolver {
 public:
  explicit MultigridSolver(const MultigridOptions& options = {});
  ~MultigridSolver();
  MultigridSolver(MultigridSolver&&) noexcept;
  MultigridSolver& operator=(MultigridSolver&&) noexcept;

  // Builds the hierarchy of a (square, symmetric, both triangles stored, positive diagonal, the
  // rows of each column in increasing order as Eigen keeps them; positive definite, or
  // semi-definite with constant_null_space). Fails when the coarsest level
  // cannot be factorized. Keeps a copy of a.
  Status compute(const Eigen::SparseMatrix<double>& a);
  // Solves a x = b; x holds the initial guess on entry (resized to zero when its size differs).
  // Fails when the tolerance is not reached within max_iterations (x then holds the last
  // iterate) or when an iterate is not finite.
  Status solve(const Eigen::VectorXd& b, Eigen::VectorXd* x) const;

  int levels() const;  // matrices in the hierarchy, the given one included
  int iterations() const { return iterations_; }  // of the last solve
  double residual() const { return residual_; }   // relative, of the last solve

 private:
  struct Hierarchy;
  MultigridOptions options_;
  std::unique_ptr<Hierarchy> hierarchy_;
  mutable int iterations_ = 0;
  mutable double residual_ = 0;
};

}  // namespace gvkit::facemap
