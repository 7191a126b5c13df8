#include "gvkit/player/mesh_level_of_detail.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

namespace gvkit::player {

double projected_grid_step_px(const MeshBuffers& mesh, const ViewCamera& camera, int width,
                              int height) {
  GVKIT_CHECK(width > 0 && height > 0);
  const size_t n = mesh.vertex_count();
  if (n == 0 || mesh.width <= 0) return 0;
  const Eigen::Matrix4f clip_from_world =
      camera.clip_from_view(static_cast<double>(width) / height) * camera.view_from_world();
  // Picture position of every vertex (NaN behind the camera).
  std::vector<Eigen::Vector2f> px(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector4f c =
        clip_from_world * Eigen::Vector4f(mesh.positions_mm[3 * i], mesh.positions_mm[3 * i + 1],
                                          mesh.positions_mm[3 * i + 2], 1.0f);
    px[i] = c.w() > 0 ? Eigen::Vector2f((c.x() / c.w() + 1) * 0.5f * width,
                                        (c.y() / c.w() + 1) * 0.5f * height)
                      : Eigen::Vector2f::Constant(NAN);
  }
  std::vector<int32_t> vertex_of(static_cast<size_t>(mesh.width) * mesh.height, -1);
  for (size_t i = 0; i < n; ++i)
    vertex_of[static_cast<size_t>(mesh.pixel_index[i])] = static_cast<int32_t>(i);
  std::vector<float> lengths;
  lengths.reserve(2 * n);
  for (size_t i = 0; i < n; ++i) {
    const int p = mesh.pixel_index[i], x = p % mesh.width, y = p / mesh.width;
    const int right = x + 1 < mesh.width ? vertex_of[static_cast<size_t>(p) + 1] : -1;
    const int below = y + 1 < mesh.height ? vertex_of[static_cast<size_t>(p) + mesh.width] : -1;
    for (const int j : {right, below}) {
      if (j < 0) continue;
      const float d = (px[i] - px[static_cast<size_t>(j)]).norm();
      if (std::isfinite(d)) lengths.push_back(d);
    }
  }
  if (lengths.empty()) return 0;
  auto mid = lengths.begin() + static_cast<ptrdiff_t>(lengths.size() / 2);
  std::nth_element(lengths.begin(), mid, lengths.end());
  return *mid;
}

int auto_mesh_stride(const MeshBuffers& mesh, const ViewCamera& camera, int width, int height,
                     int max_stride) {
  GVKIT_CHECK(max_stride >= 1);
  const double step = projected_grid_step_px(mesh, camera, width, height);
  if (!(step > 0)) return 1;
  return static_cast<int>(std::clamp<long>(std::lround(1.0 / step), 1, max_stride));
}

}  // namespace gvkit::player
