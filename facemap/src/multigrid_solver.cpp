#include "gvkit/facemap/multigrid_solver.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/SparseCholesky>

namespace gvkit::facemap {

using SparseMatrix = Eigen::SparseMatrix<double>;
using RowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

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
// diagonal[i] is the position of a_ii among column i's entries (sorted by row), so each column is
// summed in two runs, the entries above and below the diagonal, without a test per entry. With
// from_zero (x = 0 on entry, forward only) the entries below the diagonal, which multiply zeros,
// are left out: the same sums.
void gauss_seidel(const SparseMatrix& a, const std::vector<int>& diagonal,
                  const Eigen::VectorXd& inverse_diagonal, const Eigen::VectorXd& b,
                  Eigen::VectorXd* x, bool forward, bool from_zero) {
  const int n = static_cast<int>(a.cols());
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* value = a.valuePtr();
  double* xs = x->data();
  for (int step = 0; step < n; ++step) {
    const int i = forward ? step : n - 1 - step;
    double sum = b[i];
    const int d = diagonal[i];
    for (int k = outer[i]; k < d; ++k) sum -= value[k] * xs[inner[k]];
    if (!from_zero)
      for (int k = d + 1; k < outer[i + 1]; ++k) sum -= value[k] * xs[inner[k]];
    xs[i] = sum * inverse_diagonal[i];
  }
}

// r = b - A x right after a single forward sweep from zero (gauss_seidel with from_zero): the
// sweep made b_i - sum_{j<i} a_ij x_j - a_ii x_i zero, so r_i = -sum_{j>i} a_ij x_j, the entries
// below the diagonal of column i: half the work of residual_of.
void residual_after_forward_sweep(const SparseMatrix& a, const std::vector<int>& diagonal,
                                  const Eigen::VectorXd& x, Eigen::VectorXd* r) {
  const int n = static_cast<int>(a.cols());
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* value = a.valuePtr();
  const double* xs = x.data();
  r->resize(n);
  for (int i = 0; i < n; ++i) {
    double sum = 0;
    for (int k = diagonal[i] + 1; k < outer[i + 1]; ++k) sum -= value[k] * xs[inner[k]];
    (*r)[i] = sum;
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

// A sparse matrix in compressed rows built one row at a time; the entries of a row are summed
// per column and left in the order they first appeared. The sums are gathered in a dense row
// (a sparse accumulator): add() has no branch, which the choice between a new entry and an
// existing one would be, and is taken once per term of the Galerkin product.
class RowBuilder {
 public:
  RowBuilder(int rows, int cols, size_t reserve)
      : sum_(static_cast<size_t>(cols), 0.0),
        row_of_(static_cast<size_t>(cols), -1),
        columns_(static_cast<size_t>(cols) + 1) {
    outer_.reserve(rows + 1);
    outer_.push_back(0);
    inner_.reserve(reserve);
    value_.reserve(reserve);
  }
  void add(int col, double x) {
    sum_[col] += x;
    columns_[count_] = col;
    count_ += row_of_[col] != row_ ? 1 : 0;
    row_of_[col] = row_;
  }
  void end_row() {
    for (int k = 0; k < count_; ++k) {
      const int col = columns_[k];
      inner_.push_back(col);
      value_.push_back(sum_[col]);
      sum_[col] = 0.0;
    }
    count_ = 0;
    ++row_;
    outer_.push_back(static_cast<int>(inner_.size()));
  }
  // The rows built so far, in compressed form.
  const std::vector<int>& outer() const { return outer_; }
  const std::vector<int>& inner() const { return inner_; }
  const std::vector<double>& value() const { return value_; }
  // The matrix (rows x cols, row-major).
  RowMatrix finish(int cols) const {
    const int rows = static_cast<int>(outer_.size()) - 1;
    RowMatrix m(rows, cols);
    m.resizeNonZeros(static_cast<Eigen::Index>(inner_.size()));
    std::copy(outer_.begin(), outer_.end(), m.outerIndexPtr());
    std::copy(inner_.begin(), inner_.end(), m.innerIndexPtr());
    std::copy(value_.begin(), value_.end(), m.valuePtr());
    return m;
  }
  // The rows with each row's columns in increasing order, stored as the columns of a
  // column-major matrix (for a symmetric matrix, the matrix itself). Two counting sorts, by
  // column and back by row, instead of a sort per row.
  SparseMatrix sorted_rows_as_columns(int cols) const {
    const int rows = static_cast<int>(outer_.size()) - 1;
    const size_t nnz = inner_.size();
    std::vector<int> col_start(static_cast<size_t>(cols) + 1, 0);
    for (int col : inner_) ++col_start[col + 1];
    for (int c = 0; c < cols; ++c) col_start[c + 1] += col_start[c];
    std::vector<int> by_col_row(nnz);
    std::vector<double> by_col_value(nnz);
    {
      std::vector<int> fill(col_start.begin(), col_start.end() - 1);
      for (int r = 0; r < rows; ++r)
        for (int k = outer_[r]; k < outer_[r + 1]; ++k) {
          const int at = fill[inner_[k]]++;
          by_col_row[at] = r;
          by_col_value[at] = value_[k];
        }
    }
    SparseMatrix m(cols, rows);
    m.resizeNonZeros(static_cast<Eigen::Index>(nnz));
    std::copy(outer_.begin(), outer_.end(), m.outerIndexPtr());
    std::vector<int> fill(outer_.begin(), outer_.end() - 1);
    int* index = m.innerIndexPtr();
    double* values = m.valuePtr();
    for (int c = 0; c < cols; ++c)
      for (int k = col_start[c]; k < col_start[c + 1]; ++k) {
        const int at = fill[by_col_row[k]]++;
        index[at] = c;
        values[at] = by_col_value[k];
      }
    return m;
  }

 private:
  std::vector<double> sum_;   // per column, the current row's sum (0 elsewhere)
  std::vector<int> row_of_;   // per column, the last row that added to it
  std::vector<int> columns_;  // the current row's columns in the order they first appeared
  int count_ = 0, row_ = 0;
  std::vector<int> outer_, inner_;
  std::vector<double> value_;
};

// P = (I - omega D^-1 A) P_tentative, P_tentative(i, aggregate[i]) = 1; omega = 4 / (3 rho) with
// rho Gershgorin's bound on the spectral radius of D^-1 A. Rows in compressed form.
RowMatrix smoothed_prolongation(const SparseMatrix& a, const Eigen::VectorXd& inverse_diagonal,
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
  RowBuilder p(n, n_coarse, static_cast<size_t>(a.nonZeros()) / 2 + n);
  for (int i = 0; i < n; ++i) {
    p.add(aggregate_of[i], 1.0);
    const double scale = omega * inverse_diagonal[i];
    for (int k = outer[i]; k < outer[i + 1]; ++k) p.add(aggregate_of[inner[k]], -scale * value[k]);
    p.end_row();
  }
  return p.finish(n_coarse);
}

// The Galerkin coarse matrix P^T A P of a symmetric A (column i = row i), by rows: first the
// rows of A P, then each coarse row I as the sum of the rows of A P at the fine rows where
// column I of P is not zero. Symmetric; columns stored with sorted rows. *restriction gets P^T
// in rows (P's columns, which the product needs anyway).
SparseMatrix galerkin_product(const SparseMatrix& a, const RowMatrix& p, RowMatrix* restriction) {
  const int n = static_cast<int>(a.cols()), nc = static_cast<int>(p.cols());
  const int* a_outer = a.outerIndexPtr();
  const int* a_inner = a.innerIndexPtr();
  const double* a_value = a.valuePtr();
  const int* p_outer = p.outerIndexPtr();
  const int* p_inner = p.innerIndexPtr();
  const double* p_value = p.valuePtr();
  RowBuilder ap_builder(n, nc, static_cast<size_t>(p.nonZeros()) * 3);
  for (int i = 0; i < n; ++i) {
    for (int k = a_outer[i]; k < a_outer[i + 1]; ++k) {
      const int j = a_inner[k];
      const double x = a_value[k];
      for (int m = p_outer[j]; m < p_outer[j + 1]; ++m) ap_builder.add(p_inner[m], x * p_value[m]);
    }
    ap_builder.end_row();
  }
  const int* ap_outer = ap_builder.outer().data();
  const int* ap_inner = ap_builder.inner().data();
  const double* ap_value = ap_builder.value().data();
  // P's columns, the rows of the restriction P^T: a counting sort of P's entries by column.
  RowMatrix& pt = *restriction;
  pt.resize(nc, n);
  pt.resizeNonZeros(p.nonZeros());
  int* col_start = pt.outerIndexPtr();
  std::fill(col_start, col_start + nc + 1, 0);
  for (Eigen::Index m = 0; m < p.nonZeros(); ++m) ++col_start[p_inner[m] + 1];
  for (int c = 0; c < nc; ++c) col_start[c + 1] += col_start[c];
  int* col_row = pt.innerIndexPtr();
  double* col_value = pt.valuePtr();
  {
    std::vector<int> fill(col_start, col_start + nc);
    for (int i = 0; i < n; ++i)
      for (int m = p_outer[i]; m < p_outer[i + 1]; ++m) {
        const int at = fill[p_inner[m]]++;
        col_row[at] = i, col_value[at] = p_value[m];
      }
  }
  RowBuilder ac(nc, nc, static_cast<size_t>(nc) * 20);
  for (int c = 0; c < nc; ++c) {
    for (int m = col_start[c]; m < col_start[c + 1]; ++m) {
      const int i = col_row[m];
      const double x = col_value[m];
      for (int q = ap_outer[i]; q < ap_outer[i + 1]; ++q) ac.add(ap_inner[q], x * ap_value[q]);
    }
    ac.end_row();
  }
  // Symmetric: its rows are its columns.
  return ac.sorted_rows_as_columns(nc);
}

}  // namespace

struct MultigridSolver::Hierarchy {
  struct Level {
    SparseMatrix a;                    // this level's matrix
    Eigen::VectorXd inverse_diagonal;  // of a
    std::vector<int> diagonal;         // position of a_ii in a's column i
    RowMatrix p;                       // prolongation to this level from the next
    RowMatrix restriction;             // p's transpose, in rows: the restriction gathers
    // The V-cycle's work vectors (one solve at a time).
    mutable Eigen::VectorXd residual, coarse_b, coarse_x;
  };
  std::vector<Level> levels;
  Eigen::SimplicialLDLT<SparseMatrix> coarsest;
  bool pinned = false;  // the coarsest level is solved with its last unknown at 0
  int sweeps = 1;

  // x = V-cycle(b) on level l, from x = 0.
  void cycle(size_t l, const Eigen::VectorXd& b, Eigen::VectorXd* x) const {
    const Level& level = levels[l];
    if (l + 1 == levels.size()) {
      if (pinned) {
        const Eigen::Index m = b.size() - 1;
        x->resize(b.size());
        x->head(m) = coarsest.solve(b.head(m));
        (*x)[m] = 0;
      } else {
        *x = coarsest.solve(b);
      }
      return;
    }
    x->setZero(b.size());
    for (int k = 0; k < sweeps; ++k)
      gauss_seidel(level.a, level.diagonal, level.inverse_diagonal, b, x, true, k == 0);
    if (sweeps == 1)
      residual_after_forward_sweep(level.a, level.diagonal, *x, &level.residual);
    else
      residual_of(level.a, b, *x, &level.residual);
    level.coarse_b.noalias() = level.restriction * level.residual;
    cycle(l + 1, level.coarse_b, &level.coarse_x);
    x->noalias() += level.p * level.coarse_x;
    for (int k = 0; k < sweeps; ++k)
      gauss_seidel(level.a, level.diagonal, level.inverse_diagonal, b, x, false, false);
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
  // Room for every level up front: a Level is copied, not moved, when the vector grows (Eigen's
  // sparse matrices do not move without the chance of an exception).
  h->levels.reserve(static_cast<size_t>(options_.max_levels));
  SparseMatrix current = a;
  current.makeCompressed();
  for (int depth = 0;; ++depth) {
    Hierarchy::Level level;
    level.a = std::move(current);
    const int n = static_cast<int>(level.a.cols());
    level.inverse_diagonal = Eigen::VectorXd::Zero(n);
    level.diagonal.assign(n, -1);
    const int* outer = level.a.outerIndexPtr();
    const int* inner = level.a.innerIndexPtr();
    for (int i = 0; i < n; ++i) {
      for (int k = outer[i]; k < outer[i + 1]; ++k) {
        GVKIT_CHECK(k == outer[i] || inner[k] > inner[k - 1], "columns with sorted rows");
        if (inner[k] == i) level.diagonal[i] = k;
      }
      const double d = level.diagonal[i] >= 0 ? level.a.valuePtr()[level.diagonal[i]] : 0.0;
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
      h->pinned = options_.constant_null_space && n > 1;
      if (h->pinned)
        h->coarsest.compute(level.a.topLeftCorner(n - 1, n - 1));
      else
        h->coarsest.compute(level.a);
      if (h->coarsest.info() != Eigen::Success)
        return failed_precondition("multigrid: the coarsest level (" + std::to_string(n) +
                                   " unknowns) could not be factorized");
      h->levels.push_back(std::move(level));
      break;
    }
    level.p = smoothed_prolongation(level.a, level.inverse_diagonal, aggregate_of, n_coarse);
    current = galerkin_product(level.a, level.p, &level.restriction);
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
  if (options_.constant_null_space) z.array() -= z.mean();
  p = z;
  double rz = r.dot(z);
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* value = a.valuePtr();
  const int n = static_cast<int>(a.cols());
  double* xs = x->data();
  double* rs = r.data();
  const double* ps = p.data();
  double* aps = ap.data();
  while (iterations_ < options_.max_iterations) {
    ++iterations_;
    // ap = A p and p.ap in one pass; then x, r and |r|^2 in one pass.
    double p_ap = 0;
    for (int i = 0; i < n; ++i) {
      double sum = 0;
      for (int k = outer[i]; k < outer[i + 1]; ++k) sum += value[k] * ps[inner[k]];
      aps[i] = sum;
      p_ap += ps[i] * sum;
    }
    const double alpha = rz / p_ap;
    double r_squared = 0;
    for (int i = 0; i < n; ++i) {
      xs[i] += alpha * ps[i];
      rs[i] -= alpha * aps[i];
      r_squared += rs[i] * rs[i];
    }
    residual_ = std::sqrt(r_squared) / b_norm;
    if (!std::isfinite(residual_))
      return failed_precondition("multigrid: the iteration diverged (not finite)");
    if (residual_ <= options_.tolerance) return Status::ok();
    hierarchy_->cycle(0, r, &z);
    if (options_.constant_null_space) z.array() -= z.mean();
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return failed_precondition("multigrid: relative residual " + std::to_string(residual_) +
                             " after " + std::to_string(iterations_) + " iterations");
}

}  // namespace gvkit::facemap
