#include "gvkit/facemap/nearest_vertices.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

std::vector<Mesh::VertexHandle> nearest_vertices_reference(const Mesh& mesh,
                                                           const std::vector<Mesh::Point>& points,
                                                           std::vector<double>* distances) {
  std::vector<Mesh::VertexHandle> best(points.size());
  std::vector<double> best_d2(points.size(), std::numeric_limits<double>::infinity());
  for (auto v : mesh.vertices()) {
    const Mesh::Point& q = mesh.point(v);
    for (size_t k = 0; k < points.size(); ++k) {
      const double d2 = (q - points[k]).sqrnorm();
      if (d2 < best_d2[k]) best_d2[k] = d2, best[k] = v;
    }
  }
  if (distances) {
    distances->resize(points.size());
    for (size_t k = 0; k < points.size(); ++k) (*distances)[k] = std::sqrt(best_d2[k]);
  }
  return best;
}

NearestVertexGrid::NearestVertexGrid(const Mesh& mesh)
    : mesh_(&mesh), n_(static_cast<int>(mesh.n_vertices())) {
  if (n_ < 4096) return;
  scan_ = false;
  const int n = n_;
  const Mesh::Point* p = mesh.points();
  Mesh::Point lo = p[0], hi = p[0];
  for (int i = 1; i < n; ++i) {
    lo.minimize(p[i]);
    hi.maximize(p[i]);
  }
  lo_ = lo;
  // About one cell per 8 vertices over the bounding box (a surface fills few of them), so the
  // grid stays small next to the mesh.
  const Mesh::Point size = hi - lo;
  const double volume = std::max(size[0], 1e-9) * std::max(size[1], 1e-9) * std::max(size[2], 1e-9);
  cell_ = std::max(
      {std::cbrt(8.0 * volume / n), size[0] / 1000.0, size[1] / 1000.0, size[2] / 1000.0, 1e-9});
  for (int k = 0; k < 3; ++k) dims_[k] = std::clamp(static_cast<int>(size[k] / cell_) + 1, 1, 1024);
  const size_t n_cells = static_cast<size_t>(dims_[0]) * dims_[1] * dims_[2];
  // Counting sort of the vertices by cell (in index order within a cell).
  start_.assign(n_cells + 1, 0);
  in_cell_.resize(n);
  std::vector<size_t> cell_index(n);
  for (int i = 0; i < n; ++i) {
    cell_index[i] = cell_of(coord(p[i][0], 0), coord(p[i][1], 1), coord(p[i][2], 2));
    ++start_[cell_index[i] + 1];
  }
  for (size_t c = 0; c < n_cells; ++c) start_[c + 1] += start_[c];
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (int i = 0; i < n; ++i) in_cell_[fill[cell_index[i]]++] = i;
}

std::vector<Mesh::VertexHandle> NearestVertexGrid::nearest(const std::vector<Mesh::Point>& points,
                                                           std::vector<double>* distances) const {
  GVKIT_CHECK(static_cast<int>(mesh_->n_vertices()) == n_,
              "nearest vertex grid: the mesh changed since the grid was built");
  if (scan_) return nearest_vertices_reference(*mesh_, points, distances);
  const Mesh::Point* p = mesh_->points();
  const std::array<int, 3>& dims = dims_;
  std::vector<Mesh::VertexHandle> best(points.size());
  if (distances) distances->assign(points.size(), std::numeric_limits<double>::infinity());
  for (size_t k = 0; k < points.size(); ++k) {
    const Mesh::Point& q = points[k];
    double best_d2 = std::numeric_limits<double>::infinity();
    int best_i = -1;
    if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2])) {
      best[k] = Mesh::VertexHandle();
      continue;
    }
    const int cx = coord(q[0], 0), cy = coord(q[1], 1), cz = coord(q[2], 2);
    for (int r = 0;; ++r) {
      // The shell of cells at Chebyshev distance r from q's cell, clipped to the grid.
      for (int z = std::max(cz - r, 0); z <= std::min(cz + r, dims[2] - 1); ++z)
        for (int y = std::max(cy - r, 0); y <= std::min(cy + r, dims[1] - 1); ++y) {
          const bool shell_yz = std::abs(z - cz) == r || std::abs(y - cy) == r;
          const int step = shell_yz ? 1 : 2 * r;  // inside the shell only x = cx -+ r
          for (int x = cx - r; x <= cx + r; x += std::max(step, 1)) {
            if (x < 0 || x >= dims[0]) continue;
            const size_t c = cell_of(x, y, z);
            for (int j = start_[c]; j < start_[c + 1]; ++j) {
              const int i = in_cell_[j];
              const double d2 = (p[i] - q).sqrnorm();
              if (d2 < best_d2 || (d2 == best_d2 && i < best_i)) best_d2 = d2, best_i = i;
            }
          }
        }
      const bool covered = cx - r <= 0 && cy - r <= 0 && cz - r <= 0 && cx + r >= dims[0] - 1 &&
                           cy + r >= dims[1] - 1 && cz + r >= dims[2] - 1;
      if (covered) break;
      // Unsearched vertices lie outside the block of cells within r of q's cell.
      double reach = std::numeric_limits<double>::infinity();
      for (int a = 0; a < 3; ++a) {
        const int c = a == 0 ? cx : a == 1 ? cy : cz;
        const double low = lo_[a] + (c - r) * cell_, high = lo_[a] + (c + r + 1) * cell_;
        reach = std::min({reach, q[a] - low, high - q[a]});
      }
      if (best_i >= 0 && reach > 0 && reach * reach > best_d2) break;
    }
    best[k] = Mesh::VertexHandle(best_i);
    if (distances) (*distances)[k] = std::sqrt(best_d2);
  }
  return best;
}

std::vector<Mesh::VertexHandle> nearest_vertices(const Mesh& mesh,
                                                 const std::vector<Mesh::Point>& points,
                                                 std::vector<double>* distances) {
  if (mesh.n_vertices() < 4096 || points.size() < 4)
    return nearest_vertices_reference(mesh, points, distances);
  return NearestVertexGrid(mesh).nearest(points, distances);
}

}  // namespace gvkit::facemap
