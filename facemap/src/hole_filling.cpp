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
  if (max_min_weight_edges < 0)
    return invalid_argument("hole filling: max_min_weight_edges must be >= 0, got " +
                            std::to_string(max_min_weight_edges));
  if (continuity < 1 || continuity > 2)
    return invalid_argument("hole filling: continuity must be 1 or 2, got " +
                            std::to_string(continuity));
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

// cot of the angle between a and b, with the cosine clamped to +-0.999 (|cot| <= 22.3), as
// CGAL's fairing weights; 0 for a triangle without area (it has no angle to speak of).
double clamped_cotan(const Point& a, const Point& b) {
  const double norms = a.norm() * b.norm();
  if (!((a % b).norm() > 1e-9 * norms)) return 0.0;
  const double c = std::clamp((a | b) / norms, -0.999, 0.999);
  return c / std::sqrt(1.0 - c * c);
}

// Mixed Voronoi area of vertex v (Meyer et al. 2003): the Voronoi region of v inside each
// non-obtuse face, half or a quarter of an obtuse face's area.
double mixed_voronoi_area(const Mesh& mesh, Mesh::VertexHandle v) {
  double area = 0.0;
  const Point& p0 = mesh.point(v);
  for (auto h : mesh.voh_range(v)) {
    if (mesh.is_boundary(h)) continue;
    const Point& p1 = mesh.point(mesh.to_vertex_handle(h));
    const Point& p2 = mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
    const Point e1 = p1 - p0, e2 = p2 - p0, e12 = p2 - p1;
    const double d0 = e1 | e2, d1 = -(e1 | e12), d2 = e2 | e12;  // cos * lengths at p0, p1, p2
    const double twice_area = (e1 % e2).norm();
    if (d0 < 0)
      area += 0.25 * twice_area;
    else if (d1 < 0 || d2 < 0)
      area += 0.125 * twice_area;
    else if (twice_area > 0)  // (|e2|^2 cot(p1) + |e1|^2 cot(p2)) / 8
      area += (e2.sqrnorm() * d1 + e1.sqrnorm() * d2) / (8.0 * twice_area);
  }
  return area;
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

// Liepa's minimal-weight triangulation of the hole polygon (dynamic programming over the
// sub-polygons rim[i..k]): the weight of a triangulation is the largest angle between the
// normals of two adjacent triangles (the mesh's faces along the rim included), then its area.
// Chords between rim vertices that are already joined by an edge of the mesh are not used.
// kNotApplicable (nothing added) when the rim repeats a vertex or no valid triangulation exists;
// kFailed when the mesh refused a face after others were added.
enum class Triangulation { kDone, kNotApplicable, kFailed };
constexpr double kDegenerateWeight = 4.0;  // above 1 - cos of any angle
Triangulation triangulate_hole_min_weight(Mesh* mesh,
                                          const std::vector<Mesh::HalfedgeHandle>& loop) {
  const int n = static_cast<int>(loop.size());
  std::vector<Point> p(n);
  std::vector<int> rim_index(mesh->n_vertices(), -1);
  for (int i = 0; i < n; ++i) {
    const auto v = mesh->from_vertex_handle(loop[i]);
    if (rim_index[v.idx()] >= 0)
      return Triangulation::kNotApplicable;  // the rim passes twice through v
    rim_index[v.idx()] = i;
    p[i] = mesh->point(v);
  }
  // Normals of the mesh's faces along rim edge i -> i + 1 (oriented like the patch).
  std::vector<Point> outer_normal(n, Point(0, 0, 0));
  for (int i = 0; i < n; ++i) {
    const auto f = mesh->face_handle(mesh->opposite_halfedge_handle(loop[i]));
    if (f.is_valid()) outer_normal[i] = mesh->calc_face_normal(f);
  }
  // Chords that already exist as mesh edges.
  std::vector<char> chord_exists(static_cast<size_t>(n) * n, 0);
  for (int i = 0; i < n; ++i)
    for (auto w : mesh->vv_range(mesh->from_vertex_handle(loop[i]))) {
      const int k = rim_index[w.idx()];
      if (k >= 0) chord_exists[static_cast<size_t>(i) * n + k] = 1;
    }
  struct Cell {
    double max_angle = 0.0;  // 1 - cos of the largest normal angle inside rim[i..k]
    double area = 0.0;
    int apex = -1;  // -1: invalid (or k = i + 1)
    Point normal = Point(0, 0, 0);
  };
  std::vector<Cell> w(static_cast<size_t>(n) * n);
  auto at = [&](int i, int k) -> Cell& { return w[static_cast<size_t>(i) * n + k]; };
  auto side_normal = [&](int i, int k) -> const Point& {  // neighbour across chord i -> k
    return k == i + 1 ? outer_normal[i] : at(i, k).normal;
  };
  for (int d = 2; d < n; ++d)
    for (int i = 0; i + d < n; ++i) {
      const int k = i + d;
      Cell& best = at(i, k);
      const bool border = i == 0 && k == n - 1;
      if (!border && chord_exists[static_cast<size_t>(i) * n + k]) continue;
      for (int m = i + 1; m < k; ++m) {
        const Cell& left = at(i, m);
        const Cell& right = at(m, k);
        if ((m > i + 1 && left.apex < 0) || (k > m + 1 && right.apex < 0)) continue;
        Point normal = (p[m] - p[i]) % (p[k] - p[i]);
        const double twice_area = normal.norm();
        if (twice_area > 0) normal /= twice_area;
        double angle = std::max(left.max_angle, right.max_angle);
        // A triangle without area (three collinear rim points) has no normal: it weighs more
        // than any real angle (1 - cos <= 2), so it is taken only where nothing else closes the
        // hole (it had weight 1, a right angle, and won against steeper real triangles).
        const double scale = (p[m] - p[i]).sqrnorm() + (p[k] - p[i]).sqrnorm();
        if (!(twice_area > 1e-9 * scale)) angle = std::max(angle, kDegenerateWeight);
        angle = std::max(angle, 1.0 - (normal | side_normal(i, m)));
        angle = std::max(angle, 1.0 - (normal | side_normal(m, k)));
        if (border) angle = std::max(angle, 1.0 - (normal | outer_normal[n - 1]));
        const double area = left.area + right.area + 0.5 * twice_area;
        if (best.apex < 0 || angle < best.max_angle ||
            (angle == best.max_angle && area < best.area)) {
          best.max_angle = angle;
          best.area = area;
          best.apex = m;
          best.normal = normal;
        }
      }
    }
  if (at(0, n - 1).apex < 0) return Triangulation::kNotApplicable;
  // Faces in post-order: each one closes an ear of what is left of the hole.
  std::vector<Mesh::VertexHandle> vertex(n);
  for (int i = 0; i < n; ++i) vertex[i] = mesh->from_vertex_handle(loop[i]);
  std::vector<std::array<int, 3>> faces;
  std::vector<std::pair<int, int>> stack = {{0, n - 1}};
  while (!stack.empty()) {  // pre-order (i, m, k), reversed below
    const auto [i, k] = stack.back();
    stack.pop_back();
    if (k - i < 2) continue;
    const int m = at(i, k).apex;
    faces.push_back({i, m, k});
    stack.emplace_back(i, m);
    stack.emplace_back(m, k);
  }
  std::reverse(faces.begin(), faces.end());
  const int first_face = static_cast<int>(mesh->n_faces());
  for (const auto& f : faces)
    if (!mesh->add_face(vertex[f[0]], vertex[f[1]], vertex[f[2]]).is_valid())
      return static_cast<int>(mesh->n_faces()) == first_face ? Triangulation::kNotApplicable
                                                             : Triangulation::kFailed;
  return Triangulation::kDone;
}

// True when s lies inside the smallest sphere through p, q, r (the sphere on their circumcircle).
bool inside_diametral_sphere(const Point& p, const Point& q, const Point& r, const Point& s) {
  const Point a = q - p, b = r - p, n = a % b;
  const double n2 = n.sqrnorm();
  if (!(n2 > 0)) return false;
  const Point center = p + ((a.sqrnorm() * b - b.sqrnorm() * a) % n) / (2.0 * n2);
  return (s - center).sqrnorm() < (p - center).sqrnorm();
}

// Liepa's refinement of the patch faces (faces from first_patch_face on): a face is split at its
// centroid while the centroid lies farther than scale / alpha from each corner, where a rim
// vertex's scale is the mean length of its edges outside the patch and a new vertex inherits
// the mean scale of its face; split faces' edges and then all patch edges are flipped when the
// opposite vertex lies inside the sphere on an adjacent face's circumcircle.
void refine_liepa(Mesh* mesh, const std::vector<Mesh::HalfedgeHandle>& loop, int first_patch_face,
                  double alpha, bool colors) {
  const int first_new_vertex = static_cast<int>(mesh->n_vertices());
  std::vector<double> rim_scale(loop.size());
  std::vector<int> rim_slot(mesh->n_vertices(), -1);
  auto is_patch_face = [&](Mesh::FaceHandle f) {
    return f.is_valid() && f.idx() >= first_patch_face;
  };
  for (size_t i = 0; i < loop.size(); ++i) {
    const auto v = mesh->from_vertex_handle(loop[i]);
    rim_slot[v.idx()] = static_cast<int>(i);
    double sum = 0.0;
    int n = 0;
    for (auto h : mesh->voh_range(v)) {
      if (is_patch_face(mesh->face_handle(h)) &&
          is_patch_face(mesh->face_handle(mesh->opposite_halfedge_handle(h))))
        continue;
      sum += mesh->calc_edge_length(h);
      ++n;
    }
    rim_scale[i] = n > 0 ? sum / n : 0.0;
  }
  std::vector<double> new_scale;
  auto scale = [&](Mesh::VertexHandle v) {
    return v.idx() >= first_new_vertex ? new_scale[v.idx() - first_new_vertex]
                                       : rim_scale[rim_slot[v.idx()]];
  };
  auto is_rim_edge = [&](Mesh::EdgeHandle e) {
    return !is_patch_face(mesh->face_handle(mesh->halfedge_handle(e, 0))) ||
           !is_patch_face(mesh->face_handle(mesh->halfedge_handle(e, 1)));
  };
  auto relax = [&](Mesh::EdgeHandle e) {
    if (is_rim_edge(e)) return false;
    const auto h = mesh->halfedge_handle(e, 0), o = mesh->halfedge_handle(e, 1);
    const Point& p = mesh->point(mesh->to_vertex_handle(h));
    const Point& q = mesh->point(mesh->to_vertex_handle(o));
    const Point& r = mesh->point(mesh->to_vertex_handle(mesh->next_halfedge_handle(h)));
    const Point& s = mesh->point(mesh->to_vertex_handle(mesh->next_halfedge_handle(o)));
    if (!inside_diametral_sphere(p, q, r, s) && !inside_diametral_sphere(p, q, s, r)) return false;
    if (!mesh->is_flip_ok(e)) return false;
    const Point rs = s - r;  // the new edge must not be collinear with p or q
    if ((rs % (p - r)).sqrnorm() <= 1e-24 * rs.sqrnorm() * (p - r).sqrnorm() ||
        (rs % (q - r)).sqrnorm() <= 1e-24 * rs.sqrnorm() * (q - r).sqrnorm())
      return false;
    mesh->flip(e);
    return true;
  };
  for (int iteration = 0; iteration < 10; ++iteration) {
    const int n_faces = static_cast<int>(mesh->n_faces());
    bool split = false;
    for (int i = first_patch_face; i < n_faces; ++i) {
      const auto f = mesh->face_handle(i);
      std::array<Mesh::VertexHandle, 3> v;
      int j = 0;
      for (auto w : mesh->fv_range(f)) v[j++] = w;
      const Point c = (mesh->point(v[0]) + mesh->point(v[1]) + mesh->point(v[2])) / 3.0;
      const double sc = (scale(v[0]) + scale(v[1]) + scale(v[2])) / 3.0;
      bool far = true;
      for (auto w : v) {
        const double d = alpha * (c - mesh->point(w)).norm();
        far = far && d > sc && d > scale(w);
      }
      if (!far) continue;
      std::array<Mesh::EdgeHandle, 3> edges;
      j = 0;
      for (auto h : mesh->fh_range(f)) edges[j++] = mesh->edge_handle(h);
      const auto nv = mesh->split(f, c);
      new_scale.push_back(sc);
      if (colors)
        mesh->set_color(nv, (mesh->color(v[0]) + mesh->color(v[1]) + mesh->color(v[2])) / 3.0f);
      for (auto e : edges) relax(e);
      split = true;
    }
    if (!split) break;
    std::vector<Mesh::EdgeHandle> edges;  // collected first: a flip changes the faces' edges
    for (int i = first_patch_face; i < static_cast<int>(mesh->n_faces()); ++i)
      for (auto h : mesh->fh_range(mesh->face_handle(i)))
        if (h.idx() < mesh->opposite_halfedge_handle(h).idx())
          edges.push_back(mesh->edge_handle(h));
    bool flipped = false;
    for (auto e : edges) flipped |= relax(e);
    if (!flipped) break;
  }
}

// Places the vertices appended from first_new_vertex on by the fairing solve of order k =
// continuity + 1: (L M^-1)^(k-1) L x = 0 on the new vertices, with every vertex within k rings
// of them fixed (the rim and continuity rings beyond). Cotangent weights L, mixed Voronoi areas
// M. Fails when the system is singular or every choice of weights leaves the fixed hull.
Status fair_new_vertices(Mesh* mesh, int first_new_vertex, int continuity, bool colors) {
  const int n_new = static_cast<int>(mesh->n_vertices()) - first_new_vertex;
  const int order = continuity + 1;
  // Local indices in rings: the new vertices first, then each ring of neighbours in turn;
  // ring_end[r] is the number of vertices within r rings (ring_end[0] = n_new).
  std::vector<int> local(mesh->n_vertices(), -1);
  std::vector<Mesh::VertexHandle> vertex_of;
  for (int i = first_new_vertex; i < static_cast<int>(mesh->n_vertices()); ++i) {
    local[i] = static_cast<int>(vertex_of.size());
    vertex_of.push_back(mesh->vertex_handle(i));
  }
  std::vector<int> ring_end = {n_new};
  for (int r = 0; r < order; ++r) {
    const int begin = r == 0 ? 0 : ring_end[r - 1];
    for (int k = begin; k < ring_end[r]; ++k)
      for (auto w : mesh->vv_range(vertex_of[k]))
        if (local[w.idx()] < 0) {
          local[w.idx()] = static_cast<int>(vertex_of.size());
          vertex_of.push_back(w);
        }
    ring_end.push_back(static_cast<int>(vertex_of.size()));
  }
  const int n_rows = ring_end[order - 1];  // vertices whose Laplacian enters the operator
  const int n_t = ring_end[order];

  // The hull of the fixed vertices, grown by its diagonal: a solution outside it is garbage
  // from a near-singular cotan system (rims that are walls along the line of sight, slivers).
  Point lo = mesh->point(vertex_of[n_new]), hi = lo;
  for (int k = n_new; k < n_t; ++k) {
    lo.minimize(mesh->point(vertex_of[k]));
    hi.maximize(mesh->point(vertex_of[k]));
  }
  const double grow = (hi - lo).norm();
  lo -= Point(grow, grow, grow);
  hi += Point(grow, grow, grow);
  // Triangles without area among the fixed ones (a surface seen edge-on, collapsed scan
  // triangles): their signed cotangents are +-22 whatever the shape nearby.
  bool degenerate = false;
  for (int k = n_new; k < n_rows && !degenerate; ++k)
    for (auto h : mesh->voh_range(vertex_of[k])) {
      if (mesh->is_boundary(h)) continue;
      const Point& p0 = mesh->point(mesh->from_vertex_handle(h));
      const Point e1 = mesh->point(mesh->to_vertex_handle(h)) - p0;
      const Point e2 = mesh->point(mesh->to_vertex_handle(mesh->next_halfedge_handle(h))) - p0;
      if (!((e1 % e2).norm() > 1e-6 * e1.norm() * e2.norm())) degenerate = true;
    }
  // Weights, in order of preference: cotangent weights with the mixed Voronoi areas (signed,
  // as in Liepa's and CGAL's fairing); the same with each edge's weight kept positive, where
  // the rings hold triangles without area or the signed solve leaves the hull; uniform weights
  // (the graph operator, well posed with the fixed rings) when the solve still leaves the hull
  // or is not finite.
  enum class Weights { kSignedCotan, kPositiveCotan, kUniform };
  for (Weights weights = degenerate ? Weights::kPositiveCotan : Weights::kSignedCotan;;
       weights = weights == Weights::kSignedCotan ? Weights::kPositiveCotan : Weights::kUniform) {
    const bool uniform = weights == Weights::kUniform;
    std::vector<Eigen::Triplet<double>> l_triplets;
    Eigen::VectorXd inverse_mass(n_rows);
    for (int k = 0; k < n_rows; ++k) {
      const auto v = vertex_of[k];
      for (auto h : mesh->voh_range(v)) {
        const auto w = mesh->to_vertex_handle(h);
        double weight = 1.0;
        if (!uniform) {
          weight = 0.0;
          for (auto hh : {h, mesh->opposite_halfedge_handle(h)}) {
            if (mesh->is_boundary(hh)) continue;
            const Point& p = mesh->point(mesh->to_vertex_handle(mesh->next_halfedge_handle(hh)));
            weight += 0.5 * clamped_cotan(mesh->point(v) - p, mesh->point(w) - p);
          }
          if (weights == Weights::kPositiveCotan) weight = std::max(weight, 1e-6);
        }
        l_triplets.emplace_back(k, local[w.idx()], -weight);
        l_triplets.emplace_back(k, k, weight);
      }
      inverse_mass[k] = 1.0 / (uniform ? 1.0 : std::max(mixed_voronoi_area(*mesh, v), 1e-12));
    }
    Eigen::SparseMatrix<double> l(n_rows, n_t);
    l.setFromTriplets(l_triplets.begin(), l_triplets.end());
    // B = L[0, 1] M^-1 L[1, 2] ... M^-1 L[k-1, k], L[r, r+1] the rows within r rings and the
    // columns within r + 1 rings: n_new x n_t.
    Eigen::SparseMatrix<double> b = l.topRows(n_new).leftCols(ring_end[1]);
    for (int r = 1; r < order; ++r) {
      const Eigen::SparseMatrix<double> step = inverse_mass.head(ring_end[r]).asDiagonal() *
                                               l.topRows(ring_end[r]).leftCols(ring_end[r + 1]);
      b = (b * step).pruned();
    }
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
    // B is symmetric only for order 2 (L symmetric): an LDLT there, LU otherwise or on failure.
    bool solved = false;
    if (order == 2) {
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(b_uu);
      if (ldlt.info() == Eigen::Success) {
        x = ldlt.solve(rhs);
        solved = true;
      }
    }
    if (!solved) {
      Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(b_uu);
      if (lu.info() != Eigen::Success) {
        if (uniform) return failed_precondition("the fairing system is singular");
        continue;
      }
      x = lu.solve(rhs);
    }
    bool inside = x.allFinite();
    for (int k = 0; k < n_new && inside; ++k)
      for (int c = 0; c < 3; ++c) inside = inside && x(k, c) >= lo[c] && x(k, c) <= hi[c];
    if (!inside) {
      if (uniform) return failed_precondition("the fill leaves the rim's hull");
      continue;
    }
    for (int k = 0; k < n_new; ++k) {
      const auto v = vertex_of[k];
      mesh->set_point(v, Point(x(k, 0), x(k, 1), x(k, 2)));
      if (colors) {
        Mesh::Color c;
        for (int j = 0; j < 4; ++j) c[j] = std::clamp(static_cast<float>(x(k, 3 + j)), 0.0f, 1.0f);
        mesh->set_color(v, c);
      }
    }
    return Status::ok();
  }
}

}  // namespace

Status fill_hole(Mesh* mesh, Mesh::HalfedgeHandle boundary_halfedge,
                 const HoleFillingOptions& options, HoleFillingReport* report) {
  GVKIT_CHECK(mesh->is_boundary(boundary_halfedge), "fill_hole: not a boundary halfedge");
  const auto loop = loop_halfedges(*mesh, boundary_halfedge);
  const int first_new_vertex = static_cast<int>(mesh->n_vertices());
  const int first_new_face = static_cast<int>(mesh->n_faces());

  std::vector<Mesh::VertexHandle> rim;
  for (auto h : loop) rim.push_back(mesh->from_vertex_handle(h));

  // Mean normal of the faces along the rim orients the ear clipping.
  Point normal(0, 0, 0);
  for (auto h : loop) {
    const auto f = mesh->face_handle(mesh->opposite_halfedge_handle(h));
    if (f.is_valid()) normal += mesh->calc_face_normal(f);
  }
  if (normal.norm() > 0) normal.normalize();
  // New faces run along the boundary halfedges, so they are oriented like their neighbours and
  // convex corners of the hole turn about `normal`. Liepa's triangulation first (O(n^3) in the
  // rim edges n), ear clipping for larger rims or where it does not apply.
  Triangulation triangulated = Triangulation::kNotApplicable;
  if (static_cast<int>(loop.size()) <= options.max_min_weight_edges)
    triangulated = triangulate_hole_min_weight(mesh, loop);
  if (triangulated == Triangulation::kFailed ||
      (triangulated == Triangulation::kNotApplicable && !triangulate_hole(mesh, rim, normal) &&
       !triangulate_hole(mesh, rim, normal * -1.0)))
    return failed_precondition("hole of " + std::to_string(loop.size()) +
                               " rim edges could not be triangulated");

  const bool colors = options.fill_colors && mesh->has_vertex_colors();
  refine_liepa(mesh, loop, first_new_face, std::sqrt(2.0) / options.density_factor, colors);

  const int n_new = static_cast<int>(mesh->n_vertices()) - first_new_vertex;
  if (n_new > 0) {
    Status faired = fair_new_vertices(mesh, first_new_vertex, options.continuity, colors);
    // A C2 fill needs two well-shaped rings beyond the rim; where they are not (a hole near the
    // outer rim or another hole), the C1 fill of one ring is the fallback.
    if (!faired.is_ok() && options.continuity > 1)
      faired = fair_new_vertices(mesh, first_new_vertex, 1, colors);
    if (!faired.is_ok())
      return failed_precondition("hole of " + std::to_string(loop.size()) +
                                 " rim edges: " + faired.message());
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
