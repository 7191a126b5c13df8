#include "gvkit/facemap/flow_coordinates.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include "directed_edges.hpp"
#include "thread_cpu_time.hpp"

namespace gvkit::facemap {

namespace {

// Signed area of triangle k in (s, t).
double st_area(const TriSurface& s, const std::vector<double>& t,
               const std::vector<double>& corner_s, int k) {
  const auto& tri = s.triangles[k];
  const double s0 = corner_s[3 * k], t0 = t[tri[0]];
  return (corner_s[3 * k + 1] - s0) * (t[tri[2]] - t0) -
         (corner_s[3 * k + 2] - s0) * (t[tri[1]] - t0);
}

int majority_sign(const TriSurface& s, const std::vector<double>& t,
                  const std::vector<double>& corner_s) {
  int positive = 0, negative = 0;
  for (int k = 0; k < s.n_triangles(); ++k) {
    const double a = st_area(s, t, corner_s, k);
    positive += a > 0, negative += a < 0;
  }
  return positive >= negative ? 1 : -1;
}

// out[c] = value(v, psi[c]) for every corner c = 3k + j of vertex v = triangles[k][j], evaluated
// once per distinct psi of each vertex: a vertex's corners carry its psi, or psi + 1 across the
// seam, so two evaluations per vertex instead of one per corner, with the same numbers.
template <class Value>
void per_corner_values(const TriSurface& s, const std::vector<double>& psi, Value value,
                       std::vector<double>* out) {
  const int n = s.n_vertices();
  std::vector<std::array<double, 2>> x(n), y(n);
  std::vector<char> known(n, 0);
  out->resize(psi.size());
  for (int k = 0; k < s.n_triangles(); ++k)
    for (int j = 0; j < 3; ++j) {
      const int c = 3 * k + j, v = s.triangles[k][j];
      const double p = psi[c];
      int slot = 0;
      while (slot < known[v] && x[v][slot] != p) ++slot;
      if (slot < known[v]) {
        (*out)[c] = y[v][slot];
        continue;
      }
      const double result = value(v, p);
      (*out)[c] = result;
      if (known[v] < 2) x[v][known[v]] = p, y[v][known[v]] = result, ++known[v];
    }
}

}  // namespace

int count_flipped(const TriSurface& s, const std::vector<double>& t,
                  const std::vector<double>& corner_s) {
  const int sign = majority_sign(s, t, corner_s);
  int flipped = 0;
  for (int k = 0; k < s.n_triangles(); ++k) flipped += !(sign * st_area(s, t, corner_s, k) > 0);
  return flipped;
}

int untangle_flow_coordinates(const TriSurface& s, const std::vector<char>& fixed,
                              std::vector<double>* t, std::vector<double>* corner_s,
                              int max_rounds) {
  const int n = s.n_vertices();
  const int sign = majority_sign(s, *t, *corner_s);
  auto is_flipped = [&](int k) { return !(sign * st_area(s, *t, *corner_s, k) > 0); };
  std::vector<std::vector<int>> corners(n);  // per vertex: its corners 3k + j
  for (int k = 0; k < s.n_triangles(); ++k)
    for (int j = 0; j < 3; ++j) corners[s.triangles[k][j]].push_back(3 * k + j);
  std::vector<int> index(n, -1);  // region vertex -> its unknown
  std::vector<int> region;
  auto add_free_corners_of = [&](int k) {
    for (int j = 0; j < 3; ++j) {
      const int v = s.triangles[k][j];
      if (fixed[v] != 1 && index[v] < 0) {
        index[v] = static_cast<int>(region.size());
        region.push_back(v);
      }
    }
  };
  for (int k = 0; k < s.n_triangles(); ++k)
    if (is_flipped(k)) add_free_corners_of(k);
  if (region.empty()) return 0;
  // s is unwrapped per vertex: a corner's s is the vertex's s (its first corner's) plus a whole
  // number of periods, which the solve keeps.
  auto periods = [&](int c, int v) {
    return std::round((*corner_s)[c] - (*corner_s)[corners[v][0]]);
  };
  for (int round = 0; round < max_rounds; ++round) {
    // The region's uniform (Tutte) system, solved exactly: every region vertex at the mean of
    // its neighbours (per triangle corner, so an interior edge counts twice) with the vertices
    // around the region fixed. A sliding vertex keeps its t and takes the mean s of its
    // boundary neighbours only.
    const int m = static_cast<int>(region.size());
    std::vector<Eigen::Triplet<double>> a_s, a_t;
    Eigen::VectorXd b_s = Eigen::VectorXd::Zero(m), b_t = Eigen::VectorXd::Zero(m);
    for (int i = 0; i < m; ++i) {
      const int v = region[i];
      const bool slides = fixed[v] == 2;
      double degree = 0;
      for (int c : corners[v]) {
        const int k = c / 3, j = c % 3;
        const double own = periods(c, v);
        for (int step = 1; step < 3; ++step) {
          const int cw = 3 * k + (j + step) % 3, w = s.triangles[k][(j + step) % 3];
          if (slides && fixed[w] != 2) continue;
          degree += 1;
          if (index[w] >= 0) {
            a_s.emplace_back(i, index[w], -1.0);
            b_s[i] += periods(cw, w) - own;
          } else {
            b_s[i] += (*corner_s)[cw] - own;
          }
          if (slides) continue;
          if (index[w] >= 0 && fixed[w] != 2)
            a_t.emplace_back(i, index[w], -1.0);
          else
            b_t[i] += (*t)[w];
        }
      }
      if (degree == 0) degree = 1, b_s[i] = (*corner_s)[corners[v][0]];  // nothing to follow
      a_s.emplace_back(i, i, degree);
      if (slides)
        a_t.emplace_back(i, i, 1.0), b_t[i] = (*t)[v];
      else
        a_t.emplace_back(i, i, degree);
    }
    Eigen::SparseMatrix<double> ms(m, m), mt(m, m);
    ms.setFromTriplets(a_s.begin(), a_s.end());
    mt.setFromTriplets(a_t.begin(), a_t.end());
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu_s(ms), lu_t(mt);
    if (lu_s.info() != Eigen::Success || lu_t.info() != Eigen::Success) break;
    const Eigen::VectorXd new_s = lu_s.solve(b_s), new_t = lu_t.solve(b_t);
    if (!new_s.allFinite() || !new_t.allFinite()) break;
    for (int i = 0; i < m; ++i) {
      const int v = region[i];
      const double base = (*corner_s)[corners[v][0]];
      for (int c : corners[v]) (*corner_s)[c] = new_s[i] + std::round((*corner_s)[c] - base);
      (*t)[v] = new_t[i];
    }
    std::vector<int> flipped;
    for (int k = 0; k < s.n_triangles(); ++k)
      if (is_flipped(k)) flipped.push_back(k);
    if (flipped.empty()) break;
    // Grow the region by two rings around what is still flipped, twice as many every five
    // rounds: a flip can sit at the region's edge round after round, pushed ahead along a strip
    // of nearly degenerate triangles, until the region spans the strip.
    const int rings = 2 << (round / 5);
    std::vector<char> seen(s.n_triangles(), 0);
    for (int k : flipped) seen[k] = 1;
    for (int ring = 0; ring < rings && !flipped.empty(); ++ring) {
      std::vector<int> around;
      for (int k : flipped)
        for (int j = 0; j < 3; ++j)
          for (int c : corners[s.triangles[k][j]])
            if (!seen[c / 3]) seen[c / 3] = 1, around.push_back(c / 3);
      for (int k : around) add_free_corners_of(k);
      flipped = std::move(around);
    }
  }
  return static_cast<int>(region.size());
}

Result<FlowCoordinates> flow_coordinates(const FaceAnnulus& annulus,
                                         const std::map<std::string, double>& key_u,
                                         RimCorrespondence rim, double min_cotan_weight,
                                         HarmonicSolver solver) {
  const TriSurface& s = annulus.surface;
  const int n = s.n_vertices();
  FlowCoordinates out;
  out.min_cotan_weight = min_cotan_weight;
  double clock = thread_cpu_ms();
  auto lap = [&clock](double* ms) {
    const double now = thread_cpu_ms();
    *ms += now - clock;
    clock = now;
  };
  const Eigen::SparseMatrix<double> laplacian = cotan_laplacian(s, min_cotan_weight);
  lap(&out.timing.laplacian_ms);
  std::vector<char> fixed(n, 0);
  std::vector<double> value(n, 0.0);
  for (int v : annulus.outer_loop) fixed[v] = 1, value[v] = 0.0;
  for (int v : annulus.inner_loop) fixed[v] = 1, value[v] = 1.0;
  // f and psi: two systems of the same Laplacian, one elimination order (direct solves only).
  out.solver = resolve_harmonic_solver(solver, n);
  const std::vector<int> order = out.solver == HarmonicSolver::kDirect
                                     ? laplacian_elimination_order(laplacian)
                                     : std::vector<int>{};
  lap(&out.timing.order_ms);
  // The solver as given: under kAuto a multigrid iteration that fails falls back to the
  // factorization (without the shared order, which is computed for direct solves only).
  GVKIT_ASSIGN_OR_RETURN(out.t, solve_dirichlet(laplacian, fixed, value, order, solver));
  out.field_report = check_harmonic_field(s, laplacian, fixed, out.t);
  lap(&out.timing.f_ms);
  GVKIT_ASSIGN_OR_RETURN(
      std::vector<double> psi,
      harmonic_conjugate(s, laplacian, annulus.inner_loop, annulus.outer_loop, order, solver));
  lap(&out.timing.psi_ms);

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
  const DirectedEdges edges(s.triangles, n);
  auto corner = [&](int k, int v) {
    int j = 0;
    while (s.triangles[k][j] != v) ++j;
    return 3 * k + j;
  };
  std::vector<double> loop_psi(m + 1);
  for (int i = 0; i < m; ++i) {
    const int a = loop[i], b = loop[(i + 1) % m];
    const int k = edges.triangle(a, b);
    GVKIT_CHECK(k >= 0, "inner loop follows boundary edges");
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
  per_corner_values(
      s, psi, [&](int, double x) { return phi(x); }, &out.corner_s);

  // The rim's correspondence: arc length from the rim anchor, as a map of psi like phi.
  if (rim != RimCorrespondence::kFlow && annulus.rim_anchor[0] >= 0) {
    std::vector<int> outer = annulus.outer_loop;
    const int mo = static_cast<int>(outer.size());
    auto psi_step = [&](int a, int b) {  // psi(b) - psi(a) in the triangle of edge a-b
      int k = edges.triangle(a, b);
      if (k < 0) k = edges.triangle(b, a);
      GVKIT_CHECK(k >= 0, "outer loop follows boundary edges");
      return psi[corner(k, b)] - psi[corner(k, a)];
    };
    double total = 0;
    for (int i = 0; i < mo; ++i) total += psi_step(outer[i], outer[(i + 1) % mo]);
    if (total < 0) std::reverse(outer.begin(), outer.end());
    // Rotate so the anchor lies on the edge outer[0] -> outer[1], at fraction ta.
    int start = -1;
    double ta = 0;
    for (int i = 0; i < mo && start < 0; ++i) {
      const int a = outer[i], b = outer[(i + 1) % mo];
      if (a == annulus.rim_anchor[0] && b == annulus.rim_anchor[1])
        start = i, ta = annulus.rim_anchor_t;
      else if (a == annulus.rim_anchor[1] && b == annulus.rim_anchor[0])
        start = i, ta = 1.0 - annulus.rim_anchor_t;
    }
    GVKIT_CHECK(start >= 0, "the rim anchor lies on the outer loop");
    std::rotate(outer.begin(), outer.begin() + start, outer.end());
    std::vector<double> len(mo), opsi(mo + 1, 0.0);
    double length = 0;
    for (int i = 0; i < mo; ++i) {
      len[i] = (s.xyz[outer[(i + 1) % mo]] - s.xyz[outer[i]]).norm();
      length += len[i];
      opsi[i + 1] = opsi[i] + std::max(psi_step(outer[i], outer[(i + 1) % mo]), 1e-9);
    }
    for (double& x : opsi) x /= opsi[mo];
    // Table from the anchor: relative psi -> rim parameter, both over [0, 1].
    const double psi_anchor_rel = ta * opsi[1];
    std::vector<double> tx = {0.0}, tu = {0.0};
    if (rim == RimCorrespondence::kArcLength) {
      double arc_acc = (1.0 - ta) * len[0];
      for (int j = 1; j <= mo; ++j) {
        tx.push_back(opsi[j] - psi_anchor_rel);
        tu.push_back(arc_acc / length);
        if (j < mo) arc_acc += len[j];
      }
    } else {
      // Unwrapped angle around the nose tip, from the anchor direction, made non-decreasing.
      const Eigen::Vector2d& o = annulus.rim_centre;
      const Eigen::Vector2d& dir = annulus.rim_direction;
      auto angle_of = [&](const Eigen::Vector2d& p) {
        const Eigen::Vector2d r = p - o;
        return std::atan2(dir.x() * r.y() - dir.y() * r.x(), dir.dot(r));
      };
      const Eigen::Vector2d anchor_xy =
          (1.0 - ta) * s.xyz[outer[0]].head<2>() + ta * s.xyz[outer[1 % mo]].head<2>();
      double previous = angle_of(anchor_xy), total = 0;
      std::vector<double> cumulative;
      for (int j = 1; j <= mo; ++j) {
        const double a = angle_of(s.xyz[outer[j % mo]].head<2>());
        double step = a - previous;
        step -= 2 * M_PI * std::round(step / (2 * M_PI));
        total += step;
        cumulative.push_back(total);
        previous = a;
      }
      // Where the rim is not star-shaped around the nose tip the angle goes back; its running
      // maximum has flat stretches, so a fifth of arc length keeps u strictly increasing (flat
      // stretches gave near-zero-area triangles in (s, t)).
      const double sign = total < 0 ? -1.0 : 1.0;
      double running = 0, arc_acc = (1.0 - ta) * len[0];
      for (int j = 1; j <= mo; ++j) {
        running = std::clamp(std::max(running, sign * cumulative[j - 1] / (2 * M_PI)), 0.0, 1.0);
        tx.push_back(opsi[j] - psi_anchor_rel);
        tu.push_back(0.8 * running + 0.2 * arc_acc / length);
        if (j < mo) arc_acc += len[j];
      }
    }
    tx.push_back(1.0), tu.push_back(1.0);
    // Absolute psi of the anchor: psi at outer[0] in the triangle of the first edge.
    int k0 = edges.triangle(outer[0], outer[1 % mo]);
    if (k0 < 0) k0 = edges.triangle(outer[1 % mo], outer[0]);
    const double psi0 = psi[corner(k0, outer[0])] + ta * psi_step(outer[0], outer[1 % mo]);
    auto phi_rim = [&](double x) {
      const double y0 = x - psi0;
      const double shift = std::floor(y0);
      const double y = y0 - shift;
      auto hi_it = std::upper_bound(tx.begin(), tx.end(), y);
      const int hi =
          std::clamp(static_cast<int>(hi_it - tx.begin()), 1, static_cast<int>(tx.size()) - 1);
      const int lo = hi - 1;
      const double w = tx[hi] > tx[lo] ? (y - tx[lo]) / (tx[hi] - tx[lo]) : 0.0;
      return tu[lo] + std::clamp(w, 0.0, 1.0) * (tu[hi] - tu[lo]) + shift;
    };
    // The whole number of periods between the two maps that keeps them closest.
    double mean_diff = 0;
    for (int k = 0; k < 64; ++k) {
      const double x = psi0 + (k + 0.5) / 64;
      mean_diff += (phi(x) - phi_rim(x)) / 64;
    }
    const double periods = std::round(mean_diff);
    per_corner_values(
        s, psi,
        [&](int v, double x) {
          const double w = out.t[v];
          return (1.0 - w) * (phi_rim(x) + periods) + w * phi(x);
        },
        &out.corner_s);
    out.rim = rim;
  }
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
  // The inner boundary's s is the boundary correspondence; the outer boundary's s is free.
  std::vector<char> on_boundary(n, 0);
  for (int v : annulus.outer_loop) on_boundary[v] = 2;
  for (int v : annulus.inner_loop) on_boundary[v] = 1;
  lap(&out.timing.correspondence_ms);
  out.untangled_vertices = untangle_flow_coordinates(s, on_boundary, &out.t, &out.corner_s);
  out.flipped = count_flipped(s, out.t, out.corner_s);
  lap(&out.timing.untangle_ms);
  return out;
}

}  // namespace gvkit::facemap
