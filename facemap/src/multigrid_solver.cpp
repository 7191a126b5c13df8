#include "gvkit/facemap/multigrid_solver.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/SparseCholesky>

namespace gvkit::facemap {

using SparseMatrix = Eigen::SparseMatrix<double>;

namespace {

// y = b - A x for a symmetric A: row i is column i, so each entry is a gather (no scatter).
void residual_of(const SparseMatrix& a, const Eigen::VectorXd& b, const Eigen::VectorXd& x,
                 Eigen::VectorXd* r) {
  const int n = static_cast<int>(a.cols());
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* value = a.valuePtr();
  r->resize(n);
  for (int i = 0; i < n; ++i) {
    double sum = b[i];
    for (int k = outer[i]; k < outer[i + 1]; ++k) sum -= value[k] * x[inner[k]];
    (*r)[i] = sum;
  }
}

// One Gauss-Seidel sweep over the unknowns, forward or backward (a symmetric pair of sweeps
// around the coarse correction keeps the V-cycle symmetric, as conjugate gradients need).
void gauss_seidel(const SparseMatrix& a, const Eigen::VectorXd& inverse_diagonal,
                  const Eigen::VectorXd& b, Eigen::VectorXd* x, bool forward) {
  const int n = static_cast<int>(a.cols());
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* value = a.valuePtr();
  double* xs = x->data();
  for (int step = 0; step < n; ++step) {
    const int i = forward ? step : n - 1 - step;
    double sum = b[i];
    for (int k = outer[i]; k < outer[i + 1]; ++k)
      if (inner[k] != i) sum -= value[k] * xs[inner[k]];
    xs[i] = sum * inverse_diagonal[i];
  }
}

// Aggregates of the strong-connection graph (Vanek, Mandel and Brezina): a node whose strong
// neighbours are all free starts an aggregate with them; the nodes left join the aggregate of a
// strong neighbour (the strongest); what is left still forms aggregates of its free
// neighbourhoods. Returns the number of aggregates; aggregate[i] for every node.
int aggregate(const SparseMatrix& a, double threshold, std::vector<int>* aggregate_of) {
  const int n = static_cast<int>(a.cols());
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* value = a.valuePtr();
  std::vector<double> diagonal(n, 0.0);
  for (int i = 0; i < n; ++i)
    for (int k = outer[i]; k < outer[i + 1]; ++k)
      if (inner[k] == i) diagonal[i] = value[k];
  std::vector<char> strong(a.nonZeros(), 0);
  for (int i = 0; i < n; ++i)
    for (int k = outer[i]; k < outer[i + 1]; ++k) {
      const int j = inner[k];
      strong[k] = j != i && std::abs(value[k]) >= threshold * std::sqrt(diagonal[i] * diagonal[j]);
    }
  std::vector<int>& agg = *aggregate_of;
  agg.assign(n, -1);
  int count = 0;
  // Pass 1: roots with all strong neighbours free.
  for (int i = 0; i < n; ++i) {
    if (agg[i] >= 0) continue;
    bool free = true, any = false;
    for (int k = outer[i]; k < outer[i + 1] && free; ++k)
      if (strong[k]) any = true, free = agg[inner[k]] < 0;
    if (!free || !any) continue;
    agg[i] = count;
    for (int k = outer[i]; k < outer[i + 1]; ++k)
      if (strong[k]) agg[inner[k]] = count;
    ++count;
  }
  // Pass 2: join the strongest aggregated neighbour's aggregate (decided on pass 1's state).
  std::vector<int> joined(agg);
  for (int i = 0; i < n; ++i) {
    if (agg[i] >= 0) continue;
    double best = 0;
    for (int k = outer[i]; k < outer[i + 1]; ++k)
      if (strong[k] && agg[inner[k]] >= 0 && std::abs(value[k]) > best)
        best = std::abs(value[k]), joined[i] = agg[inner[k]];
  }
  agg.swap(joined);
  // Pass 3: what is left (no strong neighbour in any aggregate) forms its own aggregates.
  for (int i = 0; i < n; ++i) {
    if (agg[i] >= 0) continue;
    agg[i] = count;
    for (int k = outer[i]; k < outer[i + 1]; ++k)
      if (strong[k] && agg[inner[k]] < 0) agg[inner[k]] = count;
    ++count;
  }
  return count;
}

// P = (I - omega D^-1 A) P_tentative, P_tentative(i, aggregate[i]) = 1; omega = 4 / (3 rho) with
// rho Gershgorin's bound on the spectral radius of D^-1 A.
SparseMatrix smoothed_prolongation(const SparseMatrix& a, const Eigen::VectorXd& inverse_diagonal,
                                   const std::vector<int>& aggregate_of, int n_coarse) {
  const int n = static_cast<int>(a.cols());
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* value = a.valuePtr();
  double rho = 0;
  for (int i = 0; i < n; ++i) {
    double sum = 0;
    for (int k = outer[i]; k < outer[i + 1]; ++k) sum += std::abs(value[k]);
    rho = std::max(rho, sum * inverse_diagonal[i]);
  }
  const double omega = rho > 0 ? 4.0 / (3.0 * rho) : 0.0;
  // Row i of P (row-major build: the rows are what the formula gives).
  Eigen::SparseMatrix<double, Eigen::RowMajor> p(n, n_coarse);
  Eigen::VectorXi per_row(n);
  for (int i = 0; i < n; ++i) per_row[i] = outer[i + 1] - outer[i] + 1;
  p.reserve(per_row);
  std::vector<std::pair<int, double>> row;
  for (int i = 0; i < n; ++i) {
    row.clear();
    row.emplace_back(aggregate_of[i], 1.0);
    const double scale = omega * inverse_diagonal[i];
    for (int k = outer[i]; k < outer[i + 1]; ++k)
      row.emplace_back(aggregate_of[inner[k]], -scale * value[k]);
    std::sort(row.begin(), row.end());
    int last = -1;
    double sum = 0;
    for (const auto& [col, x] : row) {
      if (col != last && last >= 0) p.insert(i, last) = sum, sum = 0;
      last = col;
      sum += x;
    }
    if (last >= 0) p.insert(i, last) = sum;
  }
  p.makeCompressed();
  return SparseMatrix(p);
}

}  // namespace

struct MultigridSolver::Hierarchy {
  struct Level {
    SparseMatrix a;                    // this level's matrix
    Eigen::VectorXd inverse_diagonal;  // of a
    SparseMatrix p, r;                 // prolongation to this level from the next, and P^T
    // The V-cycle's work vectors (one solve at a time).
    mutable Eigen::VectorXd residual, coarse_b, coarse_x;
  };
  std::vector<Level> levels;
  Eigen::SimplicialLDLT<SparseMatrix> coarsest;
  int sweeps = 1;

  // x = V-cycle(b) on level l, from x = 0.
  void cycle(size_t l, const Eigen::VectorXd& b, Eigen::VectorXd* x) const {
    const Level& level = levels[l];
    if (l + 1 == levels.size()) {
      *x = coarsest.solve(b);
      return;
    }
    x->setZero(b.size());
    for (int k = 0; k < sweeps; ++k) gauss_seidel(level.a, level.inverse_diagonal, b, x, true);
    residual_of(level.a, b, *x, &level.residual);
    level.coarse_b.noalias() = level.r * level.residual;
    cycle(l + 1, level.coarse_b, &level.coarse_x);
    x->noalias() += level.p * level.coarse_x;
    for (int k = 0; k < sweeps; ++k) gauss_seidel(level.a, level.inverse_diagonal, b, x, false);
  }
};

Status MultigridOptions::check() const {
  if (!(strength_threshold >= 0 && strength_threshold < 1))
    return invalid_argument("multigrid: strength_threshold must be in [0, 1)");
  if (coarsest_size < 1) return invalid_argument("multigrid: coarsest_size must be >= 1");
  if (max_levels < 1) return invalid_argument("multigrid: max_levels must be >= 1");
  if (!(tolerance > 0)) return invalid_argument("multigrid: tolerance must be > 0");
  if (max_iterations < 1) return invalid_argument("multigrid: max_iterations must be >= 1");
  if (sweeps < 1) return invalid_argument("multigrid: sweeps must be >= 1");
  if (!(max_coarse_fraction > 0 && max_coarse_fraction < 1))
    return invalid_argument("multigrid: max_coarse_fraction must be in (0, 1)");
  return Status::ok();
}

MultigridSolver::MultigridSolver(const MultigridOptions& options) : options_(options) {}
MultigridSolver::~MultigridSolver() = default;
MultigridSolver::MultigridSolver(MultigridSolver&&) noexcept = default;
MultigridSolver& MultigridSolver::operator=(MultigridSolver&&) noexcept = default;

int MultigridSolver::levels() const {
  return hierarchy_ ? static_cast<int>(hierarchy_->levels.size()) : 0;
}

Status MultigridSolver::compute(const SparseMatrix& a) {
  GVKIT_RETURN_IF_ERROR(options_.check());
  GVKIT_CHECK(a.rows() == a.cols(), "a square matrix");
  auto h = std::make_unique<Hierarchy>();
  h->sweeps = options_.sweeps;
  SparseMatrix current = a;
  current.makeCompressed();
  for (int depth = 0;; ++depth) {
    Hierarchy::Level level;
    level.a = std::move(current);
    const int n = static_cast<int>(level.a.cols());
    level.inverse_diagonal = Eigen::VectorXd::Zero(n);
    for (int i = 0; i < n; ++i) {
      const double d = level.a.coeff(i, i);
      if (!(d > 0))
        return failed_precondition("multigrid: diagonal entry " + std::to_string(i) + " of level " +
                                   std::to_string(depth) + " is not positive");
      level.inverse_diagonal[i] = 1.0 / d;
    }
    const bool last = n <= options_.coarsest_size || depth + 1 >= options_.max_levels;
    std::vector<int> aggregate_of;
    const int n_coarse = last ? n : aggregate(level.a, options_.strength_threshold, &aggregate_of);
    // Coarsening that stalls (few strong connections left) ends the hierarchy.
    if (last || n_coarse > options_.max_coarse_fraction * n || n_coarse == 0) {
      h->coarsest.compute(level.a);
      if (h->coarsest.info() != Eigen::Success)
        return failed_precondition("multigrid: the coarsest level (" + std::to_string(n) +
                                   " unknowns) could not be factorized");
      h->levels.push_back(std::move(level));
      break;
    }
    level.p = smoothed_prolongation(level.a, level.inverse_diagonal, aggregate_of, n_coarse);
    level.r = level.p.transpose();
    const SparseMatrix ap = level.a * level.p;
    current = level.r * ap;
    current.makeCompressed();
    h->levels.push_back(std::move(level));
  }
  hierarchy_ = std::move(h);
  return Status::ok();
}

Status MultigridSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd* x) const {
  GVKIT_CHECK(hierarchy_, "compute() before solve()");
  const SparseMatrix& a = hierarchy_->levels[0].a;
  GVKIT_CHECK(b.size() == a.rows(), "b has one entry per unknown");
  if (x->size() != b.size()) x->setZero(b.size());
  iterations_ = 0;
  const double b_norm = b.norm();
  if (b_norm == 0) {
    x->setZero();
    residual_ = 0;
    return Status::ok();
  }
  Eigen::VectorXd r, z, p, ap(b.size());
  residual_of(a, b, *x, &r);
  residual_ = r.norm() / b_norm;
  if (residual_ <= options_.tolerance) return Status::ok();
  hierarchy_->cycle(0, r, &z);
  p = z;
  double rz = r.dot(z);
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* value = a.valuePtr();
  while (iterations_ < options_.max_iterations) {
    ++iterations_;
    for (int i = 0; i < a.cols(); ++i) {
      double sum = 0;
      for (int k = outer[i]; k < outer[i + 1]; ++k) sum += value[k] * p[inner[k]];
      ap[i] = sum;
    }
    const double alpha = rz / p.dot(ap);
    *x += alpha * p;
    r -= alpha * ap;
    residual_ = r.norm() / b_norm;
    if (!std::isfinite(residual_))
      return failed_precondition("multigrid: the iteration diverged (not finite)");
    if (residual_ <= options_.tolerance) return Status::ok();
    hierarchy_->cycle(0, r, &z);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return failed_precondition("multigrid: relative residual " + std::to_string(residual_) +
                             " after " + std::to_string(iterations_) + " iterations");
}

}  // namespace gvkit::facemap
