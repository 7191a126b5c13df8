#include "gvkit/facemap/mesh_from_scan.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

namespace gvkit::facemap {

Status MeshFromScanOptions::check() const {
  if (!(max_edge_factor > 1.0) || !std::isfinite(max_edge_factor))
    return invalid_argument("mesh from scan: max_edge_factor must be > 1, got " +
                            std::to_string(max_edge_factor));
  return Status::ok();
}

Result<ScanMesh> mesh_from_scan(const RangeScan& scan, const MeshFromScanOptions& options) {
  Result<ScanMesh> result(std::in_place);
  if (Status s = mesh_from_scan(scan, options, &*result); !s.is_ok()) result = std::move(s);
  return result;
}

Status mesh_from_scan(const RangeScan& scan, const MeshFromScanOptions& options, ScanMesh* out) {
  GVKIT_RETURN_IF_ERROR(options.check());
  const std::string frame = "frame " + std::to_string(scan.index);
  GVKIT_RETURN_IF_ERROR(scan.check().with_context(frame));
  const int rows = scan.xyz_mm.rows, cols = scan.xyz_mm.cols;
  auto valid = [&](int y, int x) { return scan.valid.at<uint8_t>(y, x) != 0; };
  auto xyz = [&](int y, int x) { return scan.xyz_mm.at<cv::Vec3f>(y, x); };

  // Pixel footprint per mm of depth: median over horizontal/vertical valid neighbours.
  std::vector<float> ratios;
  ratios.reserve(static_cast<size_t>(rows) * cols);
  for (int y = 0; y + 1 < rows; y += 2)
    for (int x = 0; x + 1 < cols; x += 2) {
      if (!valid(y, x)) continue;
      const cv::Vec3f p = xyz(y, x);
      const float z = std::abs(p[2]);
      if (!(z > 0.0f)) continue;
      if (valid(y, x + 1)) ratios.push_back(static_cast<float>(cv::norm(xyz(y, x + 1) - p)) / z);
      if (valid(y + 1, x)) ratios.push_back(static_cast<float>(cv::norm(xyz(y + 1, x) - p)) / z);
    }
  if (ratios.empty())
    return failed_precondition(frame + ": range scan has no two neighbouring valid pixels");
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  const double footprint = ratios[ratios.size() / 2];

  std::vector<Mesh::Point> points;
  std::vector<Mesh::Color> colors;
  cv::Mat index(rows, cols, CV_32S, cv::Scalar(-1));
  const bool has_texture = !scan.texture.empty();
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x) {
      if (!valid(y, x)) continue;
      const cv::Vec3f p = xyz(y, x);
      index.at<int>(y, x) = static_cast<int>(points.size());
      points.emplace_back(p[0], p[1], p[2]);
      const float t = has_texture ? std::clamp(scan.texture.at<float>(y, x), 0.0f, 1.0f) : 0.5f;
      colors.emplace_back(t, t, t, 1.0f);
    }

  // Edge test: |a - b| <= factor * footprint * depth, with room for diagonals (1.5 > sqrt 2).
  const double edge_per_depth = options.max_edge_factor * footprint * 1.5;
  auto edge_ok = [&](int a, int b) {
    const Mesh::Point d = points[a] - points[b];
    const double limit = edge_per_depth * 0.5 * (std::abs(points[a][2]) + std::abs(points[b][2]));
    return d.sqrnorm() <= limit * limit;
  };
  auto triangle_ok = [&](int a, int b, int c) {
    return edge_ok(a, b) && edge_ok(b, c) && edge_ok(c, a);
  };

  // Corners ordered so that face normals point towards the camera (-z): x right, y down.
  std::vector<std::array<int, 3>> triangles;
  triangles.reserve(static_cast<size_t>(points.size()) * 2);
  for (int y = 0; y + 1 < rows; ++y)
    for (int x = 0; x + 1 < cols; ++x) {
      const int a = index.at<int>(y, x), b = index.at<int>(y, x + 1);
      const int c = index.at<int>(y + 1, x + 1), d = index.at<int>(y + 1, x);
      const int n_valid = (a >= 0) + (b >= 0) + (c >= 0) + (d >= 0);
      if (n_valid < 3) continue;
      auto emit = [&](int p, int q, int r) {
        if (triangle_ok(p, q, r)) triangles.push_back({p, q, r});
      };
      if (n_valid == 4) {
        if ((points[a] - points[c]).sqrnorm() <= (points[b] - points[d]).sqrnorm()) {
          emit(a, c, b);
          emit(a, d, c);
        } else {
          emit(a, d, b);
          emit(b, d, c);
        }
      } else if (a < 0) {
        emit(b, d, c);
      } else if (b < 0) {
        emit(a, d, c);
      } else if (c < 0) {
        emit(a, d, b);
      } else {
        emit(a, c, b);
      }
    }
  if (triangles.empty())
    return failed_precondition(frame + ": no triangle in the range scan (" +
                               std::to_string(points.size()) + " valid pixels)");

  out->footprint_per_depth = footprint;
  // Pixels joined only diagonally, and gaps that touch at a pixel, leave vertices with several
  // open fans; a boundary loop through such a vertex is no simple polygon, and filling it as one
  // made a handle (a noisy scan's "genus 1" mask). Each keeps its largest fan.
  const int pinch_faces = open_pinched_fans(points, &triangles);
  MeshRepairOptions repair_options;
  repair_options.keep_largest_component = options.keep_largest_component;
  repair_options.check_duplicates = false;  // each 2x2 block gives its own triangles
  std::vector<int> original;
  mesh_from_triangles(points, colors, triangles, repair_options, &out->mesh, &out->repair,
                      &original);
  out->repair.pinch_faces = pinch_faces;
  std::vector<cv::Point> pixel_of_point(points.size());
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x)
      if (index.at<int>(y, x) >= 0) pixel_of_point[index.at<int>(y, x)] = {x, y};
  out->vertex_of_pixel = cv::Mat(rows, cols, CV_32S, cv::Scalar(-1));
  out->vertex_pixel.resize(original.size());
  for (size_t v = 0; v < original.size(); ++v) {
    out->vertex_pixel[v] = pixel_of_point[original[v]];
    out->vertex_of_pixel.at<int>(out->vertex_pixel[v]) = static_cast<int>(v);
  }
  return Status::ok();
}

}  // namespace gvkit::facemap
