#include "gvkit/facemap/flow_coordinates.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gvkit::facemap {

Result<FlowCoordinates> flow_coordinates(const FaceAnnulus& annulus,
                                         const std::map<std::string, double>& key_u) {
  const TriSurface& s = annulus.surface;
  const int n = s.n_vertices();
  FlowCoordinates out;
  const Eigen::SparseMatrix<double> laplacian = cotan_laplacian(s);
  std::vector<char> fixed(n, 0);
  std::vector<double> value(n, 0.0);
  for (int v : annulus.outer_loop) fixed[v] = 1, value[v] = 0.0;
  for (int v : annulus.inner_loop) fixed[v] = 1, value[v] = 1.0;
  GVKIT_ASSIGN_OR_RETURN(out.t, solve_dirichlet(laplacian, fixed, value));
  out.field_report = check_harmonic_field(s, laplacian, fixed, out.t);
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> psi,
                         harmonic_conjugate(s, laplacian, annulus.inner_loop, annulus.outer_loop));

  // Boundary parameter u along the inner loop (loop order, u(0) at the anchor key).
  const std::vector<int>& loop = annulus.inner_loop;
  const int m = static_cast<int>(loop.size());
  std::vector<double> arc(m + 1, 0.0);
  for (int i = 0; i < m; ++i)
    arc[i + 1] = arc[i] + (s.xyz[loop[(i + 1) % m]] - s.xyz[loop[i]]).norm();
  std::vector<double> u(m + 1);
  if (key_u.empty()) {
    for (int i = 0; i <= m; ++i) u[i] = arc[i] / arc[m];
    for (const auto& k : annulus.keys) out.key_u[k.name] = u[k.position];
  } else {
    const auto names = annulus.key_names();
    if (names.size() != key_u.size())
      return failed_precondition("boundary correspondence: " + std::to_string(names.size()) +
                                 " keys on this face, " + std::to_string(key_u.size()) +
                                 " on the canonical domain");
    std::vector<std::pair<int, double>> anchors;  // (loop position, u), increasing
    for (const auto& k : annulus.keys) {
      auto it = key_u.find(k.name);
      if (it == key_u.end())
        return failed_precondition("boundary correspondence: key " + k.name +
                                   " is not on the canonical domain (features out of order)");
      anchors.emplace_back(k.position, it->second);
    }
    for (size_t i = 1; i < anchors.size(); ++i)
      if (!(anchors[i].second > anchors[i - 1].second))
        return failed_precondition(
            "boundary correspondence: keys in a different order than on "
            "the canonical domain");
    anchors.emplace_back(m, anchors[0].second + 1.0);
    for (size_t i = 0; i + 1 < anchors.size(); ++i) {
      const int p0 = anchors[i].first, p1 = anchors[i + 1].first;
      const double u0 = anchors[i].second, u1 = anchors[i + 1].second;
      const double len = arc[p1] - arc[p0];
      for (int p = p0; p <= p1; ++p)
        u[p] = len > 0 ? u0 + (u1 - u0) * (arc[p] - arc[p0]) / len : u0;
    }
    out.key_u = key_u;
  }

  // psi along the inner loop: per boundary edge from the corners of its triangle.
  std::map<std::pair<int, int>, int> face_of_edge;
  for (int k = 0; k < s.n_triangles(); ++k)
    for (int j = 0; j < 3; ++j) face_of_edge[{s.triangles[k][j], s.triangles[k][(j + 1) % 3]}] = k;
  auto corner = [&](int k, int v) {
    int j = 0;
    while (s.triangles[k][j] != v) ++j;
    return 3 * k + j;
  };
  std::vector<double> loop_psi(m + 1);
  for (int i = 0; i < m; ++i) {
    const int a = loop[i], b = loop[(i + 1) % m];
    const int k = face_of_edge.at({a, b});
    if (i == 0) loop_psi[0] = psi[corner(k, a)];
    double step = psi[corner(k, b)] - psi[corner(k, a)];
    if (!(step > 0)) {
      ++out.boundary_nonmonotone;
      step = 1e-9;
    }
    loop_psi[i + 1] = loop_psi[i] + step;
  }
  // Rescale so the loop spans exactly one period.
  const double span = loop_psi[m] - loop_psi[0];
  for (int i = 0; i <= m; ++i) loop_psi[i] = loop_psi[0] + (loop_psi[i] - loop_psi[0]) / span;

  auto phi = [&](double x) {
    const double shift = std::floor(x - loop_psi[0]);
    const double y = x - shift;
    auto it = std::upper_bound(loop_psi.begin(), loop_psi.end(), y);
    const int hi = std::clamp(static_cast<int>(it - loop_psi.begin()), 1, m);
    const int lo = hi - 1;
    const double w = (y - loop_psi[lo]) / (loop_psi[hi] - loop_psi[lo]);
    return u[lo] + std::clamp(w, 0.0, 1.0) * (u[hi] - u[lo]) + shift;
  };
  out.corner_s.resize(psi.size());
  for (size_t c = 0; c < psi.size(); ++c) out.corner_s[c] = phi(psi[c]);
  // Every corner of an inner-loop vertex takes the vertex's exact boundary parameter (up to
  // whole periods), which removes solver round-off there.
  std::vector<double> boundary_u(n, std::numeric_limits<double>::quiet_NaN());
  for (int i = 0; i < m; ++i) boundary_u[loop[i]] = u[i];
  for (int k = 0; k < s.n_triangles(); ++k)
    for (int j = 0; j < 3; ++j) {
      const double uv = boundary_u[s.triangles[k][j]];
      if (std::isnan(uv)) continue;
      double& cs = out.corner_s[3 * k + j];
      cs = uv + std::round(cs - uv);
    }
  int positive = 0, negative = 0;
  for (int k = 0; k < s.n_triangles(); ++k) {
    const auto& tri = s.triangles[k];
    const double s0 = out.corner_s[3 * k], t0 = out.t[tri[0]];
    const double a = (out.corner_s[3 * k + 1] - s0) * (out.t[tri[2]] - t0) -
                     (out.corner_s[3 * k + 2] - s0) * (out.t[tri[1]] - t0);
    if (a > 0) ++positive;
    if (a < 0) ++negative;
  }
  out.flipped = s.n_triangles() - std::max(positive, negative);
  return out;
}

}  // namespace gvkit::facemap
