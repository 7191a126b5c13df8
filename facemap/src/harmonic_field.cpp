#include "gvkit/facemap/harmonic_field.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <queue>
#include <string>

#include <Eigen/Geometry>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>

#include "directed_edges.hpp"
#include "gvkit/facemap/multigrid_solver.hpp"

namespace gvkit::facemap {
namespace {

// Half cotangents of the three angles of a triangle: [k] is for the angle at corner k. A
// degenerate triangle's are 0.
std::array<double, 3> half_cotangents(const TriSurface& s, const std::array<int, 3>& t) {
  std::array<double, 3> c{};
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d a = s.xyz[t[(k + 1) % 3]] - s.xyz[t[k]];
    const Eigen::Vector3d b = s.xyz[t[(k + 2) % 3]] - s.xyz[t[k]];
    const double sin2 = a.cross(b).norm();
    c[k] = sin2 > 0 ? 0.5 * a.dot(b) / sin2 : 0.0;
  }
  return c;
}

// The free vertices' indices in the reduced system: in vertex order, or in `order` when given.
// Returns the number of free vertices.
int free_indices(const std::vector<char>& fixed, const std::vector<int>& order,
                 std::vector<int>* index) {
  const int n = static_cast<int>(fixed.size());
  index->assign(n, -1);
  int n_free = 0;
  if (order.empty()) {
    for (int i = 0; i < n; ++i)
      if (!fixed[i]) (*index)[i] = n_free++;
  } else {
    GVKIT_CHECK(static_cast<int>(order.size()) == n, "an elimination order of every vertex");
    for (int v : order)
      if (!fixed[v]) (*index)[v] = n_free++;
  }
  return n_free;
}

// L restricted to the free vertices (index[v] >= 0) with vertex v at row and column index[v]:
// what setFromTriplets of those entries gives, built column by column without the triplets.
Eigen::SparseMatrix<double> reduced_matrix(const Eigen::SparseMatrix<double>& l,
                                           const std::vector<int>& index, int n_free) {
  std::vector<int> vertex_of(n_free);
  for (int v = 0; v < static_cast<int>(index.size()); ++v)
    if (index[v] >= 0) vertex_of[index[v]] = v;
  Eigen::VectorXi count = Eigen::VectorXi::Zero(n_free);
  for (int j = 0; j < n_free; ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(l, vertex_of[j]); it; ++it)
      count[j] += index[it.row()] >= 0;
  Eigen::SparseMatrix<double> a(n_free, n_free);
  a.reserve(count);
  std::vector<std::pair<int, double>> column;
  for (int j = 0; j < n_free; ++j) {
    column.clear();
    for (Eigen::SparseMatrix<double>::InnerIterator it(l, vertex_of[j]); it; ++it)
      if (index[it.row()] >= 0) column.emplace_back(index[it.row()], it.value());
    std::sort(column.begin(), column.end());
    for (const auto& [row, x] : column) a.insert(row, j) = x;
  }
  a.makeCompressed();
  return a;
}

// Solves a x = rhs (a: the reduced system, already in elimination order when `ordered`): factorized
// directly, or by multigrid (which ignores the order).
Result<Eigen::VectorXd> factorize_and_solve(const Eigen::SparseMatrix<double>& a,
                                            const Eigen::VectorXd& rhs, bool ordered,
                                            HarmonicSolver solver, const std::string& what) {
  Eigen::VectorXd x;
  bool ok = false;
  if (resolve_harmonic_solver(solver, static_cast<int>(a.rows())) == HarmonicSolver::kMultigrid) {
    MultigridSolver multigrid;
    Status status = multigrid.compute(a);
    if (status.is_ok()) status = multigrid.solve(rhs, &x);
    if (status.is_ok()) return x;
    // kAuto falls back to the factorization; a forced multigrid reports why it failed.
    if (solver == HarmonicSolver::kMultigrid)
      return failed_precondition(what + ": " + status.message());
  }
  if (ordered) {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>>
        solver(a);
    ok = solver.info() == Eigen::Success;
    if (ok) x = solver.solve(rhs);
  } else {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(a);
    ok = solver.info() == Eigen::Success;
    if (ok) x = solver.solve(rhs);
  }
  if (!ok) return failed_precondition(what + ": the system could not be factorized");
  if (!x.allFinite()) return failed_precondition(what + ": the solution is not finite");
  return x;
}

// psi oriented: it must increase by +1 going once around inner_loop in loop order.
Result<std::vector<double>> oriented_conjugate(const TriSurface& surface,
                                               const DirectedEdges& edges,
                                               const std::vector<int>& inner_loop,
                                               std::vector<double> psi) {
  double total = 0;
  const int m = static_cast<int>(inner_loop.size());
  for (int i = 0; i < m; ++i) {
    const int u = inner_loop[i], w = inner_loop[(i + 1) % m];
    const int k = edges.triangle(u, w);
    GVKIT_CHECK(k >= 0, "inner loop follows boundary halfedges");
    const auto& t = surface.triangles[k];
    int su = 0, sw = 0;
    while (t[su] != u) ++su;
    while (t[sw] != w) ++sw;
    total += psi[3 * k + sw] - psi[3 * k + su];
  }
  if (!(std::abs(std::abs(total) - 1.0) < 1e-6))
    return failed_precondition("harmonic conjugate: period around the inner boundary is " +
                               std::to_string(total) + ", not +-1");
  if (total < 0)
    for (double& p : psi) p = -p;
  return psi;
}

}  // namespace

HarmonicSolver resolve_harmonic_solver(HarmonicSolver solver, int n_free) {
  if (solver != HarmonicSolver::kAuto) return solver;
  return n_free >= kMultigridMinVertices ? HarmonicSolver::kMultigrid : HarmonicSolver::kDirect;
}

std::vector<int> laplacian_elimination_order(const Eigen::SparseMatrix<double>& laplacian) {
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
  Eigen::AMDOrdering<int>()(laplacian, perm);
  return std::vector<int>(perm.indices().data(), perm.indices().data() + perm.size());
}

Eigen::SparseMatrix<double> cotan_laplacian(const TriSurface& surface, double min_cotan_weight) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(surface.triangles.size() * 6 + surface.xyz.size());
  for (const auto& t : surface.triangles) {
    const auto c = half_cotangents(surface, t);
    for (int k = 0; k < 3; ++k) {
      // The edge opposite corner k joins i and j.
      const int i = t[(k + 1) % 3], j = t[(k + 2) % 3];
      triplets.emplace_back(i, j, -c[k]);
      triplets.emplace_back(j, i, -c[k]);
    }
  }
  const int n = surface.n_vertices();
  for (int v = 0; v < n; ++v) triplets.emplace_back(v, v, 0.0);  // the diagonal's slot
  Eigen::SparseMatrix<double> l(n, n);
  l.setFromTriplets(triplets.begin(), triplets.end());  // the edge weights, summed, negated
  // Floor the edge weights; the diagonal is minus the sum of its column's off-diagonals.
  for (int col = 0; col < n; ++col) {
    double sum = 0;
    double* diagonal = nullptr;
    for (Eigen::SparseMatrix<double>::InnerIterator it(l, col); it; ++it) {
      if (it.row() == col) {
        diagonal = &it.valueRef();
        continue;
      }
      it.valueRef() = std::min(it.value(), -min_cotan_weight);
      sum -= it.value();
    }
    *diagonal = sum;
  }
  return l;
}

Result<std::vector<double>> solve_dirichlet(const Eigen::SparseMatrix<double>& laplacian,
                                            const std::vector<char>& fixed,
                                            const std::vector<double>& value,
                                            const std::vector<int>& order, HarmonicSolver solver) {
  const int n = static_cast<int>(laplacian.rows());
  GVKIT_CHECK(static_cast<int>(fixed.size()) == n && static_cast<int>(value.size()) == n);
  std::vector<int> index;
  const int n_free = free_indices(fixed, order, &index);
  std::vector<double> f(n);
  for (int i = 0; i < n; ++i)
    if (fixed[i]) f[i] = value[i];
  if (n_free == 0) return f;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n_free);
  for (int col = 0; col < n; ++col) {
    if (!fixed[col]) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian, col); it; ++it) {
      const int row = static_cast<int>(it.row());
      if (!fixed[row]) rhs[index[row]] -= it.value() * value[col];
    }
  }
  const Eigen::SparseMatrix<double> a = reduced_matrix(laplacian, index, n_free);
  GVKIT_ASSIGN_OR_RETURN(const Eigen::VectorXd x,
                         factorize_and_solve(a, rhs, !order.empty(), solver, "harmonic field"));
  for (int i = 0; i < n; ++i)
    if (!fixed[i]) f[i] = x[index[i]];
  return f;
}

HarmonicFieldReport check_harmonic_field(const TriSurface& surface,
                                         const Eigen::SparseMatrix<double>& laplacian,
                                         const std::vector<char>& fixed,
                                         const std::vector<double>& f) {
  HarmonicFieldReport r;
  const int n = surface.n_vertices();
  std::vector<double> lo(n, std::numeric_limits<double>::infinity()),
      hi(n, -std::numeric_limits<double>::infinity());
  for (const auto& t : surface.triangles)
    for (int k = 0; k < 3; ++k)
      for (int m = 1; m < 3; ++m) {
        const int i = t[k], j = t[(k + m) % 3];
        lo[i] = std::min(lo[i], f[j]);
        hi[i] = std::max(hi[i], f[j]);
      }
  r.min_free = std::numeric_limits<double>::infinity();
  r.max_free = -std::numeric_limits<double>::infinity();
  Eigen::VectorXd fv = Eigen::Map<const Eigen::VectorXd>(f.data(), n);
  const Eigen::VectorXd lf = laplacian * fv;
  for (int i = 0; i < n; ++i) {
    if (fixed[i]) continue;
    r.min_free = std::min(r.min_free, f[i]);
    r.max_free = std::max(r.max_free, f[i]);
    if (f[i] < lo[i] || f[i] > hi[i]) ++r.interior_extrema;
    r.residual = std::max(r.residual, std::abs(lf[i]));
  }
  return r;
}

Result<std::vector<double>> harmonic_conjugate(const TriSurface& surface,
                                               const Eigen::SparseMatrix<double>& laplacian,
                                               const std::vector<int>& inner_loop,
                                               const std::vector<int>& outer_loop,
                                               const std::vector<int>& order,
                                               HarmonicSolver solver) {
  const int n = surface.n_vertices();
  // Seam: shortest path (by length) from inner_loop[0] through interior vertices to the outer
  // boundary.
  std::vector<char> on_inner(n, 0), on_outer(n, 0);
  for (int v : inner_loop) on_inner[v] = 1;
  for (int v : outer_loop) on_outer[v] = 1;
  // The successor of each vertex per triangle, and (built only when needed) the predecessor.
  const DirectedEdges edges(surface.triangles, n);
  std::unique_ptr<DirectedEdges> reversed;
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::vector<int> parent(n, -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  const int start = inner_loop[0];
  // Dijkstra from `start` over `neighbours`, avoiding the inner boundary, to the nearest outer
  // boundary vertex; -1 when none is reachable.
  auto shortest_to_outer = [&]() {
    std::fill(dist.begin(), dist.end(), std::numeric_limits<double>::infinity());
    dist[start] = 0;
    queue = {};
    queue.emplace(0.0, start);
    while (!queue.empty()) {
      const auto [d, v] = queue.top();
      queue.pop();
      if (d > dist[v]) continue;
      if (on_outer[v]) return v;
      for (const DirectedEdges* e : {&edges, static_cast<const DirectedEdges*>(reversed.get())}) {
        if (!e) continue;
        for (int i = e->begin(v); i < e->end(v); ++i) {
          const int w = e->to(i);
          if (on_inner[w]) continue;
          const double nd = d + (surface.xyz[w] - surface.xyz[v]).norm();
          if (nd < dist[w]) dist[w] = nd, parent[w] = v, queue.emplace(nd, w);
        }
      }
    }
    return -1;
  };
  int end = shortest_to_outer();
  // edges holds only the successor of each vertex per triangle; walk both directions.
  if (end < 0) {
    std::vector<std::array<int, 3>> flipped = surface.triangles;
    for (auto& t : flipped) std::swap(t[0], t[1]);
    reversed = std::make_unique<DirectedEdges>(flipped, n);
    end = shortest_to_outer();
  }
  if (end < 0)
    return failed_precondition(
        "harmonic conjugate: the inner and outer boundaries are not "
        "connected");
  std::vector<int> seam;
  for (int v = end; v >= 0; v = parent[v]) seam.push_back(v);
  std::reverse(seam.begin(), seam.end());  // seam[0] = start on the inner boundary

  // Corners at seam vertices on the left of the seam (seen along its direction) get +1.
  std::map<std::pair<int, int>, char> is_seam_edge;
  for (size_t i = 1; i < seam.size(); ++i) {
    is_seam_edge[{seam[i - 1], seam[i]}] = 1;
    is_seam_edge[{seam[i], seam[i - 1]}] = 1;
  }
  std::vector<double> jump(surface.n_triangles() * 3, 0.0);
  for (size_t i = 0; i < seam.size(); ++i) {
    const int v = seam[i];
    // A face left of the seam at v: left of (v -> next), or of (prev -> v) at the end.
    const int first =
        i + 1 < seam.size() ? edges.triangle(v, seam[i + 1]) : edges.triangle(seam[i - 1], v);
    GVKIT_CHECK(first >= 0);
    // Flood the fan of v from that face across edges at v that are neither seam nor boundary.
    std::vector<int> stack = {first};
    std::map<int, char> visited;
    while (!stack.empty()) {
      const int k = stack.back();
      stack.pop_back();
      if (visited[k]) continue;
      visited[k] = 1;
      const auto& t = surface.triangles[k];
      int slot = 0;
      while (t[slot] != v) ++slot;
      jump[3 * k + slot] = 1.0;
      for (int w : {t[(slot + 1) % 3], t[(slot + 2) % 3]}) {
        if (is_seam_edge.count({v, w})) continue;
        for (auto e : {std::make_pair(v, w), std::make_pair(w, v)}) {
          const int f = edges.triangle(e.first, e.second);
          if (f >= 0 && !visited[f]) stack.push_back(f);
        }
      }
    }
  }

  // Minimize sum_edges w (theta_i + J_i - theta_j - J_j)^2 with theta pinned at start, w the
  // Laplacian's edge weights. J_i - J_j is the same in both triangles of an edge (an edge that
  // is not a seam edge lies in one sector of the seam's fan at each end), so each triangle adds
  // its share of the edge's weight (half of an interior edge's, all of a boundary edge's).
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < surface.n_triangles(); ++k) {
    const auto& t = surface.triangles[k];
    for (int m = 0; m < 3; ++m) {
      const int a = (m + 1) % 3, b = (m + 2) % 3;
      const double dj = jump[3 * k + a] - jump[3 * k + b];
      if (dj == 0) continue;
      const int sharing = edges.count(t[a], t[b]) + edges.count(t[b], t[a]);
      const double w = -laplacian.coeff(t[a], t[b]) / sharing;
      rhs[t[a]] -= w * dj;
      rhs[t[b]] += w * dj;
    }
  }
  std::vector<char> fixed(n, 0);
  fixed[start] = 1;
  std::vector<double> psi(surface.n_triangles() * 3);
  if (resolve_harmonic_solver(solver, n - 1) == HarmonicSolver::kMultigrid) {
    // The whole Laplacian, singular with the constants as its null space (rhs sums to 0: every
    // edge adds w dj at one end and takes it at the other): no reduced system to build, the same
    // iterations as the system with start pinned, whose solution is this one's minus a constant.
    MultigridOptions options;
    options.constant_null_space = true;
    MultigridSolver multigrid(options);
    Eigen::VectorXd theta;
    Status status = multigrid.compute(laplacian);
    if (status.is_ok()) status = multigrid.solve(rhs, &theta);
    if (status.is_ok()) {
      theta.array() -= theta[start];
      for (int k = 0; k < surface.n_triangles(); ++k)
        for (int j = 0; j < 3; ++j)
          psi[3 * k + j] = theta[surface.triangles[k][j]] + jump[3 * k + j];
      return oriented_conjugate(surface, edges, inner_loop, std::move(psi));
    }
    // kAuto falls back to the factorization below; a forced multigrid reports why it failed.
    if (solver == HarmonicSolver::kMultigrid)
      return failed_precondition("harmonic conjugate: " + status.message());
  }
  std::vector<int> index;
  const int n_free = free_indices(fixed, order, &index);
  Eigen::VectorXd b(n_free);
  for (int i = 0; i < n; ++i)
    if (!fixed[i]) b[index[i]] = rhs[i];
  const Eigen::SparseMatrix<double> a = reduced_matrix(laplacian, index, n_free);
  GVKIT_ASSIGN_OR_RETURN(const Eigen::VectorXd x,
                         factorize_and_solve(a, b, !order.empty(), solver, "harmonic conjugate"));
  for (int k = 0; k < surface.n_triangles(); ++k)
    for (int j = 0; j < 3; ++j) {
      const int v = surface.triangles[k][j];
      psi[3 * k + j] = (fixed[v] ? 0.0 : x[index[v]]) + jump[3 * k + j];
    }
  return oriented_conjugate(surface, edges, inner_loop, std::move(psi));
}

}  // namespace gvkit::facemap
