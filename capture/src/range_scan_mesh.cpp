#include "gvkit/capture/range_scan_mesh.hpp"

#include <algorithm>
#include <vector>

namespace gvkit::capture {

Mesh range_scan_mesh(const RangeScan& scan, double max_edge_mm) {
  Mesh mesh;
  mesh.request_vertex_colors();
  const int w = scan.xyz_mm.cols, h = scan.xyz_mm.rows;
  std::vector<Mesh::VertexHandle> handle(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!scan.valid.at<uint8_t>(y, x)) continue;
      const cv::Vec3f p = scan.xyz_mm.at<cv::Vec3f>(y, x);
      auto v = mesh.add_vertex(Mesh::Point(p[0], p[1], p[2]));
      const float t =
          scan.texture.empty() ? 1.0f : std::clamp(scan.texture.at<float>(y, x), 0.0f, 1.0f);
      mesh.set_color(v, Mesh::Color(t, t, t, 1.0f));
      handle[static_cast<size_t>(y) * w + x] = v;
    }
  const double max2 = max_edge_mm * max_edge_mm;
  auto close = [&](int a, int b) {
    const cv::Vec3f pa = scan.xyz_mm.at<cv::Vec3f>(a / w, a % w);
    const cv::Vec3f pb = scan.xyz_mm.at<cv::Vec3f>(b / w, b % w);
    return cv::norm(pa - pb, cv::NORM_L2SQR) <= max2;
  };
  auto triangle = [&](int a, int b, int c) {
    if (!handle[a].is_valid() || !handle[b].is_valid() || !handle[c].is_valid()) return;
    if (!close(a, b) || !close(b, c) || !close(c, a)) return;
    mesh.add_face(handle[a], handle[b], handle[c]);
  };
  for (int y = 0; y + 1 < h; ++y)
    for (int x = 0; x + 1 < w; ++x) {
      const int i = y * w + x;
      // Camera looks along +z, y down: (i, i+w, i+1) faces the camera.
      triangle(i, i + w, i + 1);
      triangle(i + 1, i + w, i + w + 1);
    }
  return mesh;
}

}  // namespace gvkit::capture
