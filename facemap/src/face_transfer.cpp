#include "gvkit/facemap/face_transfer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "gvkit/facemap/surface_distance.hpp"

namespace gvkit::facemap {

namespace {

cv::Vec3d vec(const Mesh::Point& p) { return {p[0], p[1], p[2]}; }

// Barycentric coordinates of q (on the triangle's plane) in (a, b, c).
std::array<double, 3> barycentric(const cv::Vec3d& q, const cv::Vec3d& a, const cv::Vec3d& b,
                                  const cv::Vec3d& c) {
  const cv::Vec3d v0 = b - a, v1 = c - a, v2 = q - a;
  const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1);
  const double d20 = v2.dot(v0), d21 = v2.dot(v1);
  const double den = d00 * d11 - d01 * d01;
  if (std::abs(den) < 1e-300) return {1.0, 0.0, 0.0};
  const double v = (d11 * d20 - d01 * d21) / den;
  const double w = (d00 * d21 - d01 * d20) / den;
  return {1.0 - v - w, v, w};
}

// Uniform grid over the vertices for nearest-vertex queries.
class VertexGrid {
 public:
  VertexGrid(const Mesh& mesh, double cell_mm) : mesh_(mesh), cell_(cell_mm) {
    for (auto v : mesh.vertices()) cells_[key(cell_of(vec(mesh.point(v))))].push_back(v.idx());
  }
  int nearest(const cv::Vec3d& p) const {
    const cv::Vec3i c = cell_of(p);
    int best = -1;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (int r = 0;; ++r) {
      // Every vertex within r cells has been seen once ring r is done; stop when the best is
      // nearer than the ring's inner distance.
      for (int dx = -r; dx <= r; ++dx)
        for (int dy = -r; dy <= r; ++dy)
          for (int dz = -r; dz <= r; ++dz) {
            if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != r) continue;
            auto it = cells_.find(key(c + cv::Vec3i(dx, dy, dz)));
            if (it == cells_.end()) continue;
            for (int v : it->second) {
              const cv::Vec3d d = vec(mesh_.point(Mesh::VertexHandle(v))) - p;
              const double d2 = d.dot(d);
              if (d2 < best_d2) {
                best_d2 = d2;
                best = v;
              }
            }
          }
      if (best >= 0 && std::sqrt(best_d2) <= r * cell_) return best;
      if (r > 4096) return best;
    }
  }

 private:
  cv::Vec3i cell_of(const cv::Vec3d& p) const {
    return {static_cast<int>(std::floor(p[0] / cell_)), static_cast<int>(std::floor(p[1] / cell_)),
            static_cast<int>(std::floor(p[2] / cell_))};
  }
  static int64_t key(const cv::Vec3i& c) {
    return (static_cast<int64_t>(c[0] & 0x1fffff) << 42) |
           (static_cast<int64_t>(c[1] & 0x1fffff) << 21) | static_cast<int64_t>(c[2] & 0x1fffff);
  }
  const Mesh& mesh_;
  double cell_;
  std::unordered_map<int64_t, std::vector<int>> cells_;
};

bool same_layout(const Mesh& a, const Mesh& b) {
  if (a.n_vertices() != b.n_vertices() || a.n_faces() != b.n_faces()) return false;
  for (auto f : a.faces()) {
    auto ia = a.cfv_iter(f);
    auto ib = b.cfv_iter(Mesh::FaceHandle(f.idx()));
    for (int j = 0; j < 3; ++j, ++ia, ++ib)
      if (ia->idx() != ib->idx()) return false;
  }
  return true;
}

}  // namespace

Result<std::vector<SurfaceAnchor>> anchor_points(const Mesh& surface,
                                                 const std::vector<cv::Vec3d>& points_mm) {
  if (surface.n_faces() == 0) return invalid_argument("anchor: the surface has no triangles");
  double edge_sum = 0.0;
  for (auto e : surface.edges()) edge_sum += surface.calc_edge_length(e);
  const VertexGrid grid(surface, std::max(1e-6, 2.0 * edge_sum / surface.n_edges()));
  std::vector<SurfaceAnchor> anchors(points_mm.size());
  for (size_t i = 0; i < points_mm.size(); ++i) {
    const cv::Vec3d& p = points_mm[i];
    const auto nearest = Mesh::VertexHandle(grid.nearest(p));
    // Faces of the two-ring of the nearest vertex.
    std::vector<int> faces;
    for (auto v1 : surface.vv_range(nearest))
      for (auto f : surface.vf_range(v1)) faces.push_back(f.idx());
    for (auto f : surface.vf_range(nearest)) faces.push_back(f.idx());
    double best = std::numeric_limits<double>::infinity();
    SurfaceAnchor& a = anchors[i];
    for (int f : faces) {
      cv::Vec3d c[3];
      auto fv = surface.cfv_iter(Mesh::FaceHandle(f));
      for (int j = 0; j < 3; ++j, ++fv) c[j] = vec(surface.point(*fv));
      const cv::Vec3d q = vec(closest_point_on_triangle(
          Mesh::Point(p[0], p[1], p[2]), Mesh::Point(c[0][0], c[0][1], c[0][2]),
          Mesh::Point(c[1][0], c[1][1], c[1][2]), Mesh::Point(c[2][0], c[2][1], c[2][2])));
      const double d = cv::norm(p - q);
      if (d < best) {
        best = d;
        a.face = f;
        a.barycentric = barycentric(q, c[0], c[1], c[2]);
        a.offset_mm = p - q;
      }
    }
    GVKIT_CHECK(a.face >= 0, "anchor: a vertex of the surface has no face");
  }
  return anchors;
}

cv::Vec3d evaluate_anchor(const Mesh& surface, const SurfaceAnchor& anchor) {
  cv::Vec3d q(0, 0, 0);
  auto fv = surface.cfv_iter(Mesh::FaceHandle(anchor.face));
  for (int j = 0; j < 3; ++j, ++fv) q += anchor.barycentric[j] * vec(surface.point(*fv));
  return q + anchor.offset_mm;
}

Result<CleanedFace> transfer_cleaned_face(const CleanedFace& reference, const Mesh& reference_input,
                                          const Mesh& target_input, const std::string& name,
                                          TransferStats* stats) {
  if (!same_layout(reference_input, target_input))
    return invalid_argument(name + ": not the vertex layout of the reference frame (" +
                            std::to_string(target_input.n_vertices()) + " vertices, " +
                            std::to_string(target_input.n_faces()) + " triangles vs " +
                            std::to_string(reference_input.n_vertices()) + ", " +
                            std::to_string(reference_input.n_faces()) + ")");
  std::vector<cv::Vec3d> points;
  for (auto v : reference.mesh.vertices()) points.push_back(vec(reference.mesh.point(v)));
  // Absent landmarks (NaN: a 51-point set's jaw) stay absent.
  std::vector<char> present;
  for (const auto& p : reference.landmarks.points_mm) {
    present.push_back(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]));
    if (present.back()) points.emplace_back(p);
  }
  GVKIT_ASSIGN_OR_RETURN(auto anchors, anchor_points(reference_input, points));
  CleanedFace out;
  out.mesh = reference.mesh;
  out.stats = reference.stats;
  TransferStats s;
  const size_t n = reference.mesh.n_vertices();
  for (size_t i = 0; i < n; ++i) {
    const cv::Vec3d q = evaluate_anchor(target_input, anchors[i]);
    out.mesh.set_point(Mesh::VertexHandle(static_cast<int>(i)), Mesh::Point(q[0], q[1], q[2]));
    const double off = cv::norm(anchors[i].offset_mm);
    if (off > 1e-6) ++s.off_surface_vertices;
    s.max_offset_mm = std::max(s.max_offset_mm, off);
  }
  for (size_t i = 0, k = n; i < present.size(); ++i)
    out.landmarks.points_mm.push_back(present[i]
                                          ? cv::Vec3f(evaluate_anchor(target_input, anchors[k++]))
                                          : cv::Vec3f(NAN, NAN, NAN));
  if (stats) *stats = s;
  return out;
}

}  // namespace gvkit::facemap
