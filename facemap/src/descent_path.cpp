#include "gvkit/facemap/descent_path.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include <Eigen/Geometry>

namespace gvkit::facemap {
namespace {

using Vec3 = Eigen::Vector3d;

Vec3 to_eigen(const Mesh::Point& p) { return {p[0], p[1], p[2]}; }

// The three corners of a face starting at the from_vertex of h (h must belong to the face), and
// the gradients of their barycentric coordinates.
struct FaceFrame {
  std::array<Mesh::VertexHandle, 3> v;
  std::array<Vec3, 3> grad_b;
  bool degenerate = false;
};

FaceFrame face_frame(const Mesh& mesh, Mesh::HalfedgeHandle h) {
  FaceFrame f;
  f.v[0] = mesh.from_vertex_handle(h);
  f.v[1] = mesh.to_vertex_handle(h);
  f.v[2] = mesh.to_vertex_handle(mesh.next_halfedge_handle(h));
  std::array<Vec3, 3> x;
  for (int i = 0; i < 3; ++i) x[i] = to_eigen(mesh.point(f.v[i]));
  const Vec3 n = (x[1] - x[0]).cross(x[2] - x[0]);
  const double twice_area = n.norm();
  if (twice_area < 1e-300) {
    f.degenerate = true;
    return f;
  }
  const Vec3 unit = n / twice_area;
  for (int i = 0; i < 3; ++i)
    f.grad_b[i] = unit.cross(x[(i + 2) % 3] - x[(i + 1) % 3]) / twice_area;
  return f;
}

Vec3 field_gradient(const FaceFrame& f, const std::vector<double>& field) {
  Vec3 g = Vec3::Zero();
  for (int i = 0; i < 3; ++i) g += field[f.v[i].idx()] * f.grad_b[i];
  return g;
}

using MayTouch = std::function<bool(Mesh::VertexHandle)>;

SurfacePoint at_vertex(Mesh::VertexHandle v) {
  SurfacePoint p;
  p.vertex = v;
  return p;
}

// A point on the edge of h at t, snapped to an end vertex when close to it. A path may touch
// the boundary only at its target, so it never snaps onto another boundary vertex.
SurfacePoint edge_point(const Mesh& mesh, Mesh::HalfedgeHandle h, double t, double snap,
                        const MayTouch& may_touch) {
  auto can_snap = [&](Mesh::VertexHandle v) { return !mesh.is_boundary(v) || may_touch(v); };
  SurfacePoint p;
  if (t <= snap && can_snap(mesh.from_vertex_handle(h))) {
    p.vertex = mesh.from_vertex_handle(h);
  } else if (t >= 1.0 - snap && can_snap(mesh.to_vertex_handle(h))) {
    p.vertex = mesh.to_vertex_handle(h);
  } else {
    p.halfedge = h;
    p.t = std::clamp(t, 1e-6, 1.0 - 1e-6);
  }
  return p;
}

// True when the point lies on the boundary away from the target (a cut must not touch it).
bool touches_boundary(const Mesh& mesh, const SurfacePoint& p, const MayTouch& may_touch) {
  if (p.is_vertex()) return mesh.is_boundary(p.vertex) && !may_touch(p.vertex);
  return mesh.is_boundary(mesh.edge_handle(p.halfedge)) &&
         !(may_touch(mesh.from_vertex_handle(p.halfedge)) &&
           may_touch(mesh.to_vertex_handle(p.halfedge)));
}

}  // namespace

Status DescentPathOptions::check() const {
  if (!(snap_fraction >= 0 && snap_fraction < 0.5))
    return invalid_argument("descent path: snap_fraction must be in [0, 0.5)");
  if (max_steps < 1) return invalid_argument("descent path: max_steps must be >= 1");
  return Status::ok();
}

Mesh::Point surface_point_position(const Mesh& mesh, const SurfacePoint& point) {
  if (point.is_vertex()) return mesh.point(point.vertex);
  const Mesh::Point a = mesh.point(mesh.from_vertex_handle(point.halfedge));
  const Mesh::Point b = mesh.point(mesh.to_vertex_handle(point.halfedge));
  return a * (1.0 - point.t) + b * point.t;
}

Result<std::vector<SurfacePoint>> trace_descent_path(const Mesh& mesh,
                                                     const std::vector<double>& field,
                                                     Mesh::VertexHandle start,
                                                     const std::vector<char>& target,
                                                     const DescentPathOptions& options,
                                                     const MayTouch& may_touch_boundary) {
  const MayTouch may_touch = [&](Mesh::VertexHandle v) {
    return target[v.idx()] || (may_touch_boundary && may_touch_boundary(v));
  };
  GVKIT_RETURN_IF_ERROR(options.check());
  GVKIT_CHECK(field.size() == mesh.n_vertices(), "one field value per vertex");
  GVKIT_CHECK(start.is_valid() && target.size() == mesh.n_vertices());
  const double snap = options.snap_fraction;
  std::vector<SurfacePoint> path;
  SurfacePoint current;
  current.vertex = start;
  path.push_back(current);

  for (int step = 0; step < options.max_steps; ++step) {
    if (current.is_vertex()) {
      const Mesh::VertexHandle v = current.vertex;
      if (target[v.idx()]) return path;
      const double fv = field[v.idx()];
      const Vec3 xv = to_eigen(mesh.point(v));
      // Steepest descent among the faces whose wedge at v contains -grad and the edges at v.
      double best_rate = 0;
      SurfacePoint best;
      for (auto h : mesh.voh_range(v)) {
        const Mesh::VertexHandle w = mesh.to_vertex_handle(h);
        if (target[w.idx()]) {  // the target is a neighbour: step onto it when it is downhill
          const double rate = (fv - field[w.idx()]) / (to_eigen(mesh.point(w)) - xv).norm();
          if (rate > 0) {
            best_rate = std::numeric_limits<double>::infinity();
            best = at_vertex(w);
            break;
          }
        }
        const double edge_rate = (fv - field[w.idx()]) / (to_eigen(mesh.point(w)) - xv).norm();
        if (edge_rate > best_rate && (!mesh.is_boundary(w) || may_touch(w))) {
          best_rate = edge_rate;
          best = at_vertex(w);
        }
        if (mesh.is_boundary(h)) continue;
        const FaceFrame f = face_frame(mesh, h);
        if (f.degenerate) continue;
        const Vec3 d = -field_gradient(f, field);
        const double rate = d.norm();
        if (rate <= best_rate) continue;
        double db1 = f.grad_b[1].dot(d), db2 = f.grad_b[2].dot(d);
        const double tol = 1e-12 * rate * (f.grad_b[1].norm() + f.grad_b[2].norm());
        if (db1 < -tol || db2 < -tol || db1 + db2 <= 0) continue;
        db1 = std::max(db1, 0.0), db2 = std::max(db2, 0.0);
        // Leaves through the opposite edge (v1 -> v2) at t = db2 / (db1 + db2).
        const SurfacePoint exit =
            edge_point(mesh, mesh.next_halfedge_handle(h), db2 / (db1 + db2), snap, may_touch);
        if (touches_boundary(mesh, exit, may_touch)) continue;
        best_rate = rate;
        best = exit;
      }
      if (best_rate <= 0)
        return failed_precondition(
            "descent path: stuck at a local minimum (vertex " + std::to_string(v.idx()) + " at " +
            std::to_string(xv.x()) + " " + std::to_string(xv.y()) + " " + std::to_string(xv.z()) +
            (mesh.is_boundary(v) ? ", on the boundary" : "") + ") before reaching the target");
      current = best;
    } else {
      // On an edge, arriving from the face of current.halfedge: continue into the other face.
      const Mesh::HalfedgeHandle h = current.halfedge;
      const Mesh::HalfedgeHandle o = mesh.opposite_halfedge_handle(h);
      const Mesh::VertexHandle a = mesh.from_vertex_handle(h), b = mesh.to_vertex_handle(h);
      auto slide_down = [&] { return at_vertex(field[a.idx()] <= field[b.idx()] ? a : b); };
      if (mesh.is_boundary(o)) {
        current = slide_down();
      } else {
        // Face of o: corners (b, a, c); our point has barycentrics (t, 1 - t, 0).
        const FaceFrame f = face_frame(mesh, o);
        const Mesh::VertexHandle c = f.v[2];
        if (target[c.idx()]) {
          current = at_vertex(c);
        } else if (f.degenerate) {
          current = slide_down();
        } else {
          const Vec3 d = -field_gradient(f, field);
          const double db_b = f.grad_b[0].dot(d), db_a = f.grad_b[1].dot(d),
                       db_c = f.grad_b[2].dot(d);
          const double b_b = current.t, b_a = 1.0 - current.t;
          if (db_c <= 1e-12 * d.norm() * (1.0 + f.grad_b[2].norm())) {
            current = slide_down();  // the flow converges onto this edge: follow it down
          } else {
            const double lambda_a = db_a < 0 ? b_a / -db_a : INFINITY;
            const double lambda_b = db_b < 0 ? b_b / -db_b : INFINITY;
            if (lambda_a <= lambda_b) {
              // a's coordinate reaches 0: exit on edge (c -> b) = prev(o).
              const double nb = b_b + lambda_a * db_b, nc = lambda_a * db_c;
              current =
                  edge_point(mesh, mesh.prev_halfedge_handle(o), nb / (nb + nc), snap, may_touch);
            } else {
              // b's coordinate reaches 0: exit on edge (a -> c) = next(o).
              const double na = b_a + lambda_b * db_a, nc = lambda_b * db_c;
              current =
                  edge_point(mesh, mesh.next_halfedge_handle(o), nc / (na + nc), snap, may_touch);
            }
          }
        }
      }
    }
    if (current.is_vertex() && path.back().is_vertex() && current.vertex == path.back().vertex)
      continue;
    if (!current.is_vertex() && mesh.is_boundary(mesh.edge_handle(current.halfedge)) &&
        target[mesh.from_vertex_handle(current.halfedge).idx()] &&
        target[mesh.to_vertex_handle(current.halfedge).idx()]) {
      path.push_back(current);
      return path;
    }
    if (touches_boundary(mesh, current, may_touch))
      return failed_precondition(
          "descent path: the path runs into a boundary (vertex or edge "
          "near vertex " +
          std::to_string(path.back().is_vertex() ? path.back().vertex.idx() : -1) +
          ") before reaching the target");
    path.push_back(current);
  }
  return failed_precondition("descent path: did not reach the target in " +
                             std::to_string(options.max_steps) + " steps");
}

}  // namespace gvkit::facemap
