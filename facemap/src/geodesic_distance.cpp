#include "gvkit/facemap/geodesic_distance.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <utility>

#include <Eigen/CholmodSupport>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "gvkit/facemap/intrinsic_triangulation.hpp"

namespace gvkit::facemap {

Status HeatGeodesicsOptions::check() const {
  if (!(time_factor > 0.0) || !std::isfinite(time_factor))
    return invalid_argument("heat geodesics: time_factor must be > 0, got " +
                            std::to_string(time_factor));
  return Status::ok();
}

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

// One factorised symmetric positive definite system, by the chosen back end.
class SpdSolver {
 public:
  SpdSolver(const SparseMatrix& a, SparseSolverKind kind) : kind_(kind) {
    if (kind_ == SparseSolverKind::kCholmod) {
      cholmod_ = std::make_unique<Eigen::CholmodSimplicialLLT<SparseMatrix>>();
      cholmod_->compute(a);
      GVKIT_CHECK(cholmod_->info() == Eigen::Success,
                  "heat geodesics: CHOLMOD factorisation failed");
    } else {
      ldlt_ = std::make_unique<Eigen::SimplicialLDLT<SparseMatrix>>();
      ldlt_->compute(a);
      GVKIT_CHECK(ldlt_->info() == Eigen::Success, "heat geodesics: LDLT factorisation failed");
    }
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const {
    return kind_ == SparseSolverKind::kCholmod ? Eigen::VectorXd(cholmod_->solve(b))
                                               : Eigen::VectorXd(ldlt_->solve(b));
  }

 private:
  SparseSolverKind kind_;
  std::unique_ptr<Eigen::CholmodSimplicialLLT<SparseMatrix>> cholmod_;
  std::unique_ptr<Eigen::SimplicialLDLT<SparseMatrix>> ldlt_;
};

}  // namespace

struct HeatGeodesics::Impl {
  IntrinsicTriangulation tri;
  int n = 0;
  double t = 0.0;
  std::vector<int> component;     // per vertex; -1 for vertices in no face
  std::vector<char> on_boundary;  // per vertex
  std::unique_ptr<SpdSolver> heat_neumann, heat_dirichlet, poisson;
};

HeatGeodesics::HeatGeodesics(const Mesh& mesh, const HeatGeodesicsOptions& options)
    : impl_(std::make_unique<Impl>()) {
  GVKIT_CHECK(options.check().is_ok(), options.check().message());
  GVKIT_CHECK(mesh.n_faces() > 0, "heat geodesics: mesh without faces");
  Impl& s = *impl_;
  s.tri = IntrinsicTriangulation(mesh);
  if (options.intrinsic_delaunay) s.tri.flip_to_delaunay();
  const Mesh& m = s.tri.mesh();
  s.n = static_cast<int>(m.n_vertices());

  // Components by flood fill over edges.
  s.component.assign(s.n, -1);
  s.on_boundary.assign(s.n, 0);
  int n_components = 0;
  for (auto v : m.vertices()) {
    if (m.is_boundary(v) && !m.is_isolated(v)) s.on_boundary[v.idx()] = 1;
    if (s.component[v.idx()] >= 0 || m.is_isolated(v)) continue;
    std::vector<Mesh::VertexHandle> stack{v};
    s.component[v.idx()] = n_components;
    while (!stack.empty()) {
      auto u = stack.back();
      stack.pop_back();
      for (auto w : m.vv_range(u))
        if (s.component[w.idx()] < 0) {
          s.component[w.idx()] = n_components;
          stack.push_back(w);
        }
    }
    ++n_components;
  }

  const double h = s.tri.mean_edge_length_mm();
  s.t = options.time_factor * h * h;

  std::vector<Eigen::Triplet<double>> l_triplets, m_triplets;
  s.tri.cotan_laplacian(&l_triplets);
  s.tri.lumped_mass(&m_triplets);
  SparseMatrix laplacian(s.n, s.n), mass(s.n, s.n);
  laplacian.setFromTriplets(l_triplets.begin(), l_triplets.end());
  mass.setFromTriplets(m_triplets.begin(), m_triplets.end());
  // Isolated vertices get a unit diagonal so every system stays definite.
  SparseMatrix identity_isolated(s.n, s.n);
  {
    std::vector<Eigen::Triplet<double>> id;
    for (int i = 0; i < s.n; ++i)
      if (s.component[i] < 0) id.emplace_back(i, i, 1.0);
    identity_isolated.setFromTriplets(id.begin(), id.end());
  }
  const SparseMatrix heat = mass + s.t * laplacian + identity_isolated;
  s.heat_neumann = std::make_unique<SpdSolver>(heat, options.solver);

  if (options.average_boundary_conditions &&
      std::any_of(s.on_boundary.begin(), s.on_boundary.end(), [](char b) { return b != 0; })) {
    // Dirichlet u = 0 on the boundary: those rows and columns become identity.
    std::vector<Eigen::Triplet<double>> d;
    for (int k = 0; k < heat.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(heat, k); it; ++it) {
        const bool bi = s.on_boundary[it.row()], bj = s.on_boundary[it.col()];
        if (!bi && !bj) d.emplace_back(it.row(), it.col(), it.value());
      }
    for (int i = 0; i < s.n; ++i)
      if (s.on_boundary[i]) d.emplace_back(i, i, 1.0);
    SparseMatrix dirichlet(s.n, s.n);
    dirichlet.setFromTriplets(d.begin(), d.end());
    s.heat_dirichlet = std::make_unique<SpdSolver>(dirichlet, options.solver);
  }

  // The cotan Laplacian is singular (constants); a tiny shift makes it definite without
  // changing the solution beyond round-off, as the result is shifted afterwards anyway.
  double mean_diagonal = 0.0;
  for (int i = 0; i < s.n; ++i) mean_diagonal += laplacian.coeff(i, i);
  mean_diagonal = std::max(mean_diagonal / s.n, 1e-300);
  SparseMatrix shift(s.n, s.n);
  shift.setIdentity();
  s.poisson = std::make_unique<SpdSolver>(
      SparseMatrix(laplacian + (1e-10 * mean_diagonal) * shift + identity_isolated),
      options.solver);
}

HeatGeodesics::~HeatGeodesics() = default;
HeatGeodesics::HeatGeodesics(HeatGeodesics&&) noexcept = default;
HeatGeodesics& HeatGeodesics::operator=(HeatGeodesics&&) noexcept = default;

int HeatGeodesics::intrinsic_flips() const { return impl_->tri.flips(); }
double HeatGeodesics::time_mm2() const { return impl_->t; }

std::vector<double> HeatGeodesics::distance(const std::vector<Mesh::VertexHandle>& sources) const {
  const Impl& s = *impl_;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> result(s.n, kInf);
  if (sources.empty()) return result;

  Eigen::VectorXd delta = Eigen::VectorXd::Zero(s.n);
  bool source_on_boundary = false;
  for (auto v : sources) {
    GVKIT_CHECK(v.is_valid() && v.idx() < s.n, "heat geodesics: source vertex out of range");
    if (s.component[v.idx()] < 0) continue;
    delta[v.idx()] = 1.0;
    source_on_boundary |= s.on_boundary[v.idx()] != 0;
  }
  Eigen::VectorXd u = s.heat_neumann->solve(delta);
  if (s.heat_dirichlet && !source_on_boundary) u = 0.5 * (u + s.heat_dirichlet->solve(delta));

  // Integrated divergence of the normalised negative gradient, per vertex.
  Eigen::VectorXd divergence = Eigen::VectorXd::Zero(s.n);
  s.tri.accumulate_unit_gradient_divergence(u, &divergence);
  const Eigen::VectorXd phi = s.poisson->solve(-divergence);

  // Shift each component so its sources sit at zero on average.
  const int n_components = 1 + *std::max_element(s.component.begin(), s.component.end());
  std::vector<double> source_sum(std::max(n_components, 0), 0.0);
  std::vector<int> source_count(std::max(n_components, 0), 0);
  for (auto v : sources) {
    const int c = s.component[v.idx()];
    if (c < 0) continue;
    source_sum[c] += phi[v.idx()];
    ++source_count[c];
  }
  for (int i = 0; i < s.n; ++i) {
    const int c = s.component[i];
    if (c < 0 || source_count[c] == 0) continue;
    result[i] = std::max(0.0, phi[i] - source_sum[c] / source_count[c]);
  }
  for (auto v : sources)
    if (s.component[v.idx()] >= 0) result[v.idx()] = 0.0;
  return result;
}

}  // namespace gvkit::facemap
