#include "gvkit/facemap/face_boundaries.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Geometry>

#include "gvkit/core/mesh_topology.hpp"

namespace gvkit::facemap {
namespace {

Eigen::Vector3d to_eigen(const Mesh::Point& p) { return {p[0], p[1], p[2]}; }

std::string fmt(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", x);
  return buf;
}

}  // namespace

Status FaceBoundaryOptions::check() const {
  if (!(landmark_tolerance_mm > 0))
    return invalid_argument("face boundaries: landmark tolerance must be > 0 mm");
  if (!(min_triangle_area_mm2 >= 0))
    return invalid_argument("face boundaries: minimum triangle area must be >= 0");
  return Status::ok();
}

int FaceBoundaries::loop_of_landmark(int landmark) {
  if (landmark >= 36 && landmark <= 41) return kEyeRight;
  if (landmark >= 42 && landmark <= 47) return kEyeLeft;
  if (landmark >= 48 && landmark <= 67) return kMouth;
  return -1;
}

LoopPoint closest_loop_point(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop,
                             const Eigen::Vector3d& p, double* distance) {
  LoopPoint best;
  double best_d2 = std::numeric_limits<double>::infinity();
  const int n = static_cast<int>(loop.size());
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d a = to_eigen(mesh.point(loop[i]));
    const Eigen::Vector3d b = to_eigen(mesh.point(loop[(i + 1) % n]));
    const Eigen::Vector3d ab = b - a;
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    const double d2 = (a + t * ab - p).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = {i, t};
    }
  }
  if (distance) *distance = std::sqrt(best_d2);
  return best;
}

Result<FaceBoundaries> find_face_boundaries(const Mesh& mesh, const FaceLandmarks& landmarks,
                                            const FaceBoundaryOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  if (mesh.n_faces() == 0) return failed_precondition("face mesh has no triangles");
  if (static_cast<int>(landmarks.points_mm.size()) != FaceLandmarks::kCount)
    return failed_precondition("landmarks: need 68 points_mm, got " +
                               std::to_string(landmarks.points_mm.size()));
  for (auto f : mesh.faces()) {
    std::array<Eigen::Vector3d, 3> x;
    int k = 0;
    for (auto v : mesh.fv_range(f)) x[k++] = to_eigen(mesh.point(v));
    const double area = 0.5 * (x[1] - x[0]).cross(x[2] - x[0]).norm();
    if (!(area > options.min_triangle_area_mm2))
      return failed_precondition("face mesh: degenerate triangle " + std::to_string(f.idx()) +
                                 " (area " + std::to_string(area) + " mm^2)");
  }
  const MeshTopology topology = mesh_topology(mesh);
  if (topology.components != 1)
    return failed_precondition("face mesh: " + std::to_string(topology.components) +
                               " connected components, need 1");
  if (topology.boundary_loops != 4)
    return failed_precondition("face mesh: " + std::to_string(topology.boundary_loops) +
                               " boundary loops, need 4 (rim, two eyes, mouth)");
  if (topology.genus != 0)
    return failed_precondition("face mesh: genus " + std::to_string(topology.genus) + ", need 0");
  std::vector<std::vector<Mesh::VertexHandle>> loops = boundary_loops(mesh);
  // boundary_loops may order a loop either way; make each follow its boundary halfedges.
  for (auto& loop : loops) {
    const auto h = mesh.find_halfedge(loop[0], loop[1]);
    if (!h.is_valid() || !mesh.is_boundary(h)) std::reverse(loop.begin() + 1, loop.end());
  }

  auto mean_distance = [&](const std::vector<Mesh::VertexHandle>& loop, int first, int last) {
    double sum = 0;
    for (int i = first; i <= last; ++i) {
      const cv::Vec3f& q = landmarks.points_mm[i];
      double d = 0;
      closest_loop_point(mesh, loop, Eigen::Vector3d(q[0], q[1], q[2]), &d);
      sum += d;
    }
    return sum / (last - first + 1);
  };
  auto nearest_loop = [&](int first, int last) {
    int best = 0;
    double best_d = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 4; ++i) {
      const double d = mean_distance(loops[i], first, last);
      if (d < best_d) best_d = d, best = i;
    }
    return best;
  };
  const int eye_right = nearest_loop(36, 41), eye_left = nearest_loop(42, 47),
            mouth = nearest_loop(60, 67);
  if (eye_right == eye_left || eye_right == mouth || eye_left == mouth)
    return failed_precondition(
        "landmarks: the eyes and the mouth do not name three different boundary loops");
  const int rim = 6 - eye_right - eye_left - mouth;
  auto length = [&](const std::vector<Mesh::VertexHandle>& loop) {
    double sum = 0;
    for (size_t i = 0; i < loop.size(); ++i)
      sum += (mesh.point(loop[(i + 1) % loop.size()]) - mesh.point(loop[i])).norm();
    return sum;
  };
  for (int i : {eye_right, eye_left, mouth})
    if (length(loops[i]) >= length(loops[rim]))
      return failed_precondition(
          "face mesh: the rim (the loop no landmark names) is not the "
          "longest boundary loop");
  FaceBoundaries out;
  out.loops[FaceBoundaries::kRim] = loops[rim];
  out.loops[FaceBoundaries::kEyeRight] = loops[eye_right];
  out.loops[FaceBoundaries::kEyeLeft] = loops[eye_left];
  out.loops[FaceBoundaries::kMouth] = loops[mouth];
  for (int lm : kBoundaryKeyLandmarks) {
    const cv::Vec3f& q = landmarks.points_mm[lm];
    double d = 0;
    closest_loop_point(mesh, out.loops[FaceBoundaries::loop_of_landmark(lm)],
                       Eigen::Vector3d(q[0], q[1], q[2]), &d);
    if (!(d <= options.landmark_tolerance_mm))
      return failed_precondition("landmark " + std::to_string(lm) + " is " + fmt(d) +
                                 " mm from the boundary it names (tolerance " +
                                 fmt(options.landmark_tolerance_mm) + " mm)");
  }
  return out;
}

}  // namespace gvkit::facemap
