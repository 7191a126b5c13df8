#include "gvkit/facemap/hole_filling.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <set>
#include <string>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>

namespace gvkit::facemap {

Status HoleFillingOptions::check() const {
  if (max_hole_edges < 0)
    return invalid_argument("hole filling: max_hole_edges must be >= 0, got " +
                            std::to_string(max_hole_edges));
  if (!(density_factor >= 0.25 && density_factor <= 8.0))
    return invalid_argument("hole filling: density_factor must be in [0.25, 8], got " +
                            std::to_string(density_factor));
  if (solve_iterations < 1 || solve_iterations > 10)
    return invalid_argument("hole filling: solve_iterations must be in [1, 10], got " +
                            std::to_string(solve_iterations));
  return Status::ok();
}

namespace {

using Point = Mesh::Point;

// Boundary loop starting at boundary halfedge h, as halfedges.
std::vector<Mesh::HalfedgeHandle> loop_halfedges(const Mesh& mesh, Mesh::HalfedgeHandle h) {
  std::vector<Mesh::HalfedgeHandle> loop;
  auto it = h;
  do {
    loop.push_back(it);
    it = mesh.next_halfedge_handle(it);
  } while (it != h && loop.size() <= mesh.n_halfedges());
  return loop;
}

double cotan(const Point& a, const Point& b) {  // cot of the angle between a and b
  const double s = (a % b).norm();
  return (a | b) / std::max(s, 1e-12 * a.norm() * b.norm() + 1e-300);
}

// Greedy ear clipping of the hole: repeatedly cut the ear with the smallest interior angle
// (measured against the hole's mean normal). Returns false when stuck.
bool triangulate_hole(Mesh* mesh, std::vector<Mesh::VertexHandle> poly, const Point& normal) {
  while (poly.size() > 3) {
    const size_t n = poly.size();
    std::vector<std::pair<double, size_t>> ears;
    ears.reserve(n);
    for (size_t i = 0; i < n; ++i) {
      const Point& p0 = mesh->point(poly[(i + n - 1) % n]);
      const Point& p1 = mesh->point(poly[i]);
      const Point& p2 = mesh->point(poly[(i + 1) % n]);
      const Point a = p1 - p0, b = p2 - p1;
      const double turning = std::atan2((a % b) | normal, a | b);  // > 0: convex corner
      ears.emplace_back(std::numbers::pi - turning, i);
    }
    std::sort(ears.begin(), ears.end());
    bool cut = false;
    for (const auto& [angle, i] : ears) {
      const auto v0 = poly[(i + n - 1) % n], v1 = poly[i], v2 = poly[(i + 1) % n];
      // The new edge v2 -> v0 must not exist yet (it would become non-manifold).
      if (mesh->find_halfedge(v2, v0).is_valid() || mesh->find_halfedge(v0, v2).is_valid())
        continue;
      if (!mesh->add_face(v0, v1, v2).is_valid()) continue;
      poly.erase(poly.begin() + static_cast<long>(i));
      cut = true;
      break;
    }
    if (!cut) return false;
  }
  return mesh->add_face(poly[0], poly[1], poly[2]).is_valid();
}

// Sum of the cotangents of the angles opposite edge e (< 0: not Delaunay).
double opposite_cotan_sum(const Mesh& mesh, Mesh::EdgeHandle e) {
  double sum = 0.0;
  for (int side = 0; side < 2; ++side) {
    const auto h = mesh.halfedge_handle(e, side);
    const auto opposite = mesh.to_vertex_handle(mesh.next_halfedge_handle(h));
    const Point& p = mesh.point(opposite);
    sum +=
        cotan(mesh.point(mesh.from_vertex_handle(h)) - p, mesh.point(mesh.to_vertex_handle(h)) - p);
  }
  return sum;
}

}  // namespace

Status fill_hole(Mesh* mesh, Mesh::HalfedgeHandle boundary_halfedge,
                 const HoleFillingOptions& options, HoleFillingReport* report) {
  GVKIT_CHECK(mesh->is_boundary(boundary_halfedge), "fill_hole: not a boundary halfedge");
  const auto loop = loop_halfedges(*mesh, boundary_halfedge);
  const int first_new_vertex = static_cast<int>(mesh->n_vertices());
  const int first_new_face = static_cast<int>(mesh->n_faces());

  std::vector<Mesh::VertexHandle> rim;
  double rim_length = 0.0;
  for (auto h : loop) {
    rim.push_back(mesh->from_vertex_handle(h));
    rim_length += mesh->calc_edge_length(h);
  }
  const double target = options.density_factor * rim_length / static_cast<double>(loop.size());

  // Mean normal of the faces along the rim orients the ear clipping.
  Point normal(0, 0, 0);
  for (auto h : loop) {
    const auto f = mesh->face_handle(mesh->opposite_halfedge_handle(h));
    if (f.is_valid()) normal += mesh->calc_face_normal(f);
  }
  if (normal.norm() > 0) normal.normalize();
  // New faces run along the boundary halfedges, so they are oriented like their neighbours and
  // convex corners of the hole turn about `normal`.
  if (!triangulate_hole(mesh, rim, normal) && !triangulate_hole(mesh, rim, normal * -1.0))
    return failed_precondition("hole of " + std::to_string(loop.size()) +
                               " rim edges could not be triangulated");

  Mesh::Color mean_color(0, 0, 0, 0);
  const bool colors = options.fill_colors && mesh->has_vertex_colors();
  if (colors) {
    for (auto v : rim) mean_color += mesh->color(v);
    mean_color /= static_cast<float>(rim.size());
  }
  auto is_patch_face = [&](Mesh::FaceHandle f) {
    return f.is_valid() && f.idx() >= first_new_face;
  };
  auto is_patch_edge = [&](Mesh::EdgeHandle e) {
    return !mesh->is_boundary(e) && is_patch_face(mesh->face_handle(mesh->halfedge_handle(e, 0))) &&
           is_patch_face(mesh->face_handle(mesh->halfedge_handle(e, 1)));
  };
  // Edges of the patch faces (faces are appended, so the patch is a tail of the face list).
  auto patch_edges = [&] {
    std::vector<Mesh::EdgeHandle> edges;
    for (int i = first_new_face; i < static_cast<int>(mesh->n_faces()); ++i)
      for (auto h : mesh->fh_range(mesh->face_handle(i))) {
        const auto e = mesh->edge_handle(h);
        if (is_patch_edge(e) && mesh->halfedge_handle(e, 0) == h) edges.push_back(e);
      }
    return edges;
  };
  auto delaunay_flips = [&] {
    for (int pass = 0; pass < 10; ++pass) {
      int flips = 0;
      for (auto e : patch_edges()) {
        // Never flip away a rim-to-rim edge pair that would reconnect existing vertices.
        if (opposite_cotan_sum(*mesh, e) < -1e-9 && mesh->is_flip_ok(e)) {
          mesh->flip(e);
          ++flips;
        }
      }
      if (flips == 0) break;
    }
  };

  // Refinement: split long patch edges, restore Delaunay, relax new vertices.
  delaunay_flips();
  for (int iteration = 0; iteration < 30; ++iteration) {
    std::vector<Mesh::EdgeHandle> long_edges;
    for (auto e : patch_edges())
      if (mesh->calc_edge_length(e) > 4.0 / 3.0 * target) long_edges.push_back(e);
    if (long_edges.empty()) break;
    for (auto e : long_edges) {
      const auto h = mesh->halfedge_handle(e, 0);
      const Point mid =
          0.5 * (mesh->point(mesh->from_vertex_handle(h)) + mesh->point(mesh->to_vertex_handle(h)));
      Mesh::Color c = mean_color;
      if (colors)
        c = 0.5f *
            (mesh->color(mesh->from_vertex_handle(h)) + mesh->color(mesh->to_vertex_handle(h)));
      const auto v = mesh->split(e, mid);
      if (colors) mesh->set_color(v, c);
    }
    delaunay_flips();
    for (int relax = 0; relax < 3; ++relax)
      for (int i = first_new_vertex; i < static_cast<int>(mesh->n_vertices()); ++i) {
        const auto v = mesh->vertex_handle(i);
        Point sum(0, 0, 0);
        int n = 0;
        for (auto w : mesh->vv_range(v)) {
          sum += mesh->point(w);
          ++n;
        }
        if (n > 0) mesh->set_point(v, sum / n);
      }
    delaunay_flips();
  }

  // Bi-Laplacian solve for the new vertices. Local indices: new vertices first, then the rest of
  // the vertices within two rings of them (the rim and one ring beyond, held fixed).
  const int n_new = static_cast<int>(mesh->n_vertices()) - first_new_vertex;
  if (n_new > 0) {
    std::vector<int> local(mesh->n_vertices(), -1);
    std::vector<Mesh::VertexHandle> vertex_of;
    for (int i = first_new_vertex; i < static_cast<int>(mesh->n_vertices()); ++i) {
      local[i] = static_cast<int>(vertex_of.size());
      vertex_of.push_back(mesh->vertex_handle(i));
    }
    // S: new vertices and their neighbours (the rim); T: S and the neighbours of S.
    std::vector<Mesh::VertexHandle> s_set(vertex_of.begin(), vertex_of.end());
    auto add_local = [&](Mesh::VertexHandle w) {
      if (local[w.idx()] >= 0) return false;
      local[w.idx()] = static_cast<int>(vertex_of.size());
      vertex_of.push_back(w);
      return true;
    };
    for (int i = 0; i < n_new; ++i)
      for (auto w : mesh->vv_range(vertex_of[i]))
        if (add_local(w)) s_set.push_back(w);
    for (size_t k = n_new; k < s_set.size(); ++k)
      for (auto w : mesh->vv_range(s_set[k])) add_local(w);
    const int n_s = static_cast<int>(s_set.size()), n_t = static_cast<int>(vertex_of.size());
    // s_set and vertex_of share the first n_s entries (S is added before the outer ring).

    // The hull of the fixed vertices, grown by its diagonal: a solution outside it is garbage
    // from a near-singular cotan system (rims that are walls along the line of sight, slivers).
    Point lo = mesh->point(vertex_of[n_new]), hi = lo;
    for (int k = n_new; k < n_t; ++k) {
      lo.minimize(mesh->point(vertex_of[k]));
      hi.maximize(mesh->point(vertex_of[k]));
    }
    const Point grow = hi - lo;
    lo -= grow;
    hi += grow;
    // Cotan weights first; uniform weights (the graph bi-Laplacian, always well posed with two
    // fixed rings) when the cotan solve leaves the hull or is not finite.
    bool uniform = false;
    for (int solve = 0; solve < options.solve_iterations; ++solve) {
      std::vector<Eigen::Triplet<double>> l_triplets;
      Eigen::VectorXd mass = Eigen::VectorXd::Zero(n_s);
      for (int k = 0; k < n_s; ++k) {
        const auto v = s_set[k];
        for (auto h : mesh->voh_range(v)) {
          const auto w = mesh->to_vertex_handle(h);
          double weight = 0.0;
          for (auto hh : {h, mesh->opposite_halfedge_handle(h)}) {
            if (mesh->is_boundary(hh)) continue;
            const auto o = mesh->to_vertex_handle(mesh->next_halfedge_handle(hh));
            const Point& p = mesh->point(o);
            weight += 0.5 * cotan(mesh->point(v) - p, mesh->point(w) - p);
          }
          weight = std::max(weight, 1e-6);  // keep the operator definite on poor triangles
          if (uniform) weight = 1.0;
          l_triplets.emplace_back(k, local[w.idx()], -weight);
          l_triplets.emplace_back(k, k, weight);
        }
        for (auto f : mesh->vf_range(v)) mass[k] += mesh->calc_face_area(f) / 3.0;
        mass[k] = uniform ? 1.0 : std::max(mass[k], 1e-12);
      }
      Eigen::SparseMatrix<double> l(n_s, n_t);
      l.setFromTriplets(l_triplets.begin(), l_triplets.end());
      const Eigen::SparseMatrix<double> l_us = l.topRows(n_new).leftCols(n_s);
      Eigen::SparseMatrix<double> b = l_us * mass.cwiseInverse().asDiagonal() * l;  // n_new x n_t
      const Eigen::SparseMatrix<double> b_uu = b.leftCols(n_new);
      const Eigen::SparseMatrix<double> b_uk = b.rightCols(n_t - n_new);
      const int channels = colors ? 7 : 3;
      Eigen::MatrixXd known(n_t - n_new, channels);
      for (int k = n_new; k < n_t; ++k) {
        const auto v = vertex_of[k];
        for (int c = 0; c < 3; ++c) known(k - n_new, c) = mesh->point(v)[c];
        if (colors)
          for (int c = 0; c < 4; ++c) known(k - n_new, 3 + c) = mesh->color(v)[c];
      }
      const Eigen::MatrixXd rhs = -(b_uk * known);
      Eigen::MatrixXd x;
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(b_uu);
      if (ldlt.info() == Eigen::Success) {
        x = ldlt.solve(rhs);
      } else {
        Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(b_uu);
        if (lu.info() != Eigen::Success)
          return failed_precondition("hole of " + std::to_string(loop.size()) +
                                     " rim edges: bi-Laplacian system is singular");
        x = lu.solve(rhs);
      }
      bool inside = x.allFinite();
      for (int k = 0; k < n_new && inside; ++k)
        for (int c = 0; c < 3; ++c) inside = inside && x(k, c) >= lo[c] && x(k, c) <= hi[c];
      if (!inside) {
        if (uniform)
          return failed_precondition("hole of " + std::to_string(loop.size()) +
                                     " rim edges: the fill leaves the rim's hull");
        uniform = true;
        --solve;  // the same solve again with uniform weights
        continue;
      }
      for (int k = 0; k < n_new; ++k) {
        const auto v = vertex_of[k];
        mesh->set_point(v, Point(x(k, 0), x(k, 1), x(k, 2)));
        if (colors) {
          Mesh::Color c;
          for (int j = 0; j < 4; ++j)
            c[j] = std::clamp(static_cast<float>(x(k, 3 + j)), 0.0f, 1.0f);
          mesh->set_color(v, c);
        }
      }
    }
  }

  if (report) {
    ++report->holes_filled;
    report->vertices_added += n_new;
    report->faces_added += static_cast<int>(mesh->n_faces()) - first_new_face;
    report->hole_rim_edges.push_back(static_cast<int>(loop.size()));
  }
  return Status::ok();
}

Result<HoleFillingReport> fill_holes(Mesh* mesh, const HoleFillingOptions& options) {
  return fill_holes(mesh, options, {});
}

Result<HoleFillingReport> fill_holes(Mesh* mesh, const HoleFillingOptions& options,
                                     const std::vector<Mesh::HalfedgeHandle>& left_open) {
  GVKIT_RETURN_IF_ERROR(options.check());
  std::vector<char> open_halfedge(mesh->n_halfedges(), 0);
  for (auto h : left_open) {
    GVKIT_CHECK(
        h.is_valid() && h.idx() < static_cast<int>(mesh->n_halfedges()) && mesh->is_boundary(h),
        "fill_holes: left_open holds a halfedge that is not on a boundary");
    open_halfedge[h.idx()] = 1;
  }
  // Boundary loops by their first halfedge, with their length in mm.
  std::vector<std::pair<double, Mesh::HalfedgeHandle>> loops;
  std::vector<char> visited(mesh->n_halfedges(), 0), loop_open;
  for (auto h : mesh->halfedges()) {
    if (!mesh->is_boundary(h) || visited[h.idx()]) continue;
    double length = 0.0;
    char open = 0;
    for (auto l : loop_halfedges(*mesh, h)) {
      visited[l.idx()] = 1;
      length += mesh->calc_edge_length(l);
      open |= open_halfedge[l.idx()];
    }
    // The loop's first halfedge stands for it from here on: mark it when the loop stays open.
    if (open) open_halfedge[h.idx()] = 1;
    loops.emplace_back(length, h);
  }
  auto is_left_open = [&](size_t i) { return open_halfedge[loops[i].second.idx()] != 0; };
  HoleFillingReport report;
  if (loops.size() <= 1) return report;
  std::sort(loops.begin(), loops.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  // Room for the fills up front (estimated from each hole's vector area and target edge), so
  // the mesh's arrays do not grow, and get copied, one split at a time.
  {
    double new_vertices = 0.0;
    for (size_t i = 1; i < loops.size(); ++i) {
      if (is_left_open(i)) continue;
      const auto hole = loop_halfedges(*mesh, loops[i].second);
      Point area(0, 0, 0);
      const Point& origin = mesh->point(mesh->from_vertex_handle(hole.front()));
      for (auto h : hole)
        area += (mesh->point(mesh->from_vertex_handle(h)) - origin) %
                (mesh->point(mesh->to_vertex_handle(h)) - origin);
      const double target = options.density_factor * loops[i].first / hole.size();
      new_vertices += 2.5 * 0.5 * area.norm() / (0.43 * target * target) + hole.size();
    }
    const size_t k = static_cast<size_t>(new_vertices);
    mesh->reserve(mesh->n_vertices() + k, mesh->n_edges() + 3 * k, mesh->n_faces() + 2 * k);
  }
  std::set<int> rim_vertices;
  for (auto h : loop_halfedges(*mesh, loops[0].second))
    rim_vertices.insert(mesh->from_vertex_handle(h).idx());
  for (size_t i = 1; i < loops.size(); ++i) {
    if (is_left_open(i)) {
      ++report.holes_left_open;
      continue;
    }
    const auto hole = loop_halfedges(*mesh, loops[i].second);
    int touching_vertex = -1;
    for (auto h : hole)
      if (rim_vertices.count(mesh->from_vertex_handle(h).idx()))
        touching_vertex = mesh->from_vertex_handle(h).idx();
    if (touching_vertex >= 0) {
      if (options.fail_on_rim_touching_holes)
        return failed_precondition("a hole of " + std::to_string(hole.size()) +
                                   " edges touches the outer rim at vertex " +
                                   std::to_string(touching_vertex));
      ++report.holes_touching_rim;
      continue;
    }
    if (options.max_hole_edges > 0 && static_cast<int>(hole.size()) > options.max_hole_edges) {
      ++report.holes_skipped;
      continue;
    }
    GVKIT_RETURN_IF_ERROR(fill_hole(mesh, loops[i].second, options, &report));
  }
  return report;
}

}  // namespace gvkit::facemap
