#include "nearest_point_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "gvkit/core/status.hpp"

namespace gvkit::bench {

NearestPointGrid::NearestPointGrid(std::vector<cv::Vec3f> points, double cell_mm)
    : points_(std::move(points)), cell_mm_(cell_mm) {
  GVKIT_CHECK(cell_mm > 0, "cell size must be > 0");
  if (points_.empty()) return;
  cv::Vec3d lo(points_[0]), hi(points_[0]);
  for (const cv::Vec3f& p : points_)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], static_cast<double>(p[a]));
      hi[a] = std::max(hi[a], static_cast<double>(p[a]));
    }
  origin_ = lo;
  hi_cell_ = cell_of(
      cv::Vec3f(static_cast<float>(hi[0]), static_cast<float>(hi[1]), static_cast<float>(hi[2])));
  std::vector<uint64_t> keys(points_.size());
  for (size_t i = 0; i < points_.size(); ++i) {
    const Cell c = cell_of(points_[i]);
    keys[i] = key(c.x, c.y, c.z);
  }
  order_.resize(points_.size());
  std::iota(order_.begin(), order_.end(), 0);
  std::stable_sort(order_.begin(), order_.end(),
                   [&](int32_t a, int32_t b) { return keys[a] < keys[b]; });
  for (size_t i = 0; i < order_.size();) {
    size_t j = i;
    while (j < order_.size() && keys[order_[j]] == keys[order_[i]]) ++j;
    cells_[keys[order_[i]]] = {static_cast<int32_t>(i), static_cast<int32_t>(j)};
    i = j;
  }
}

NearestPointGrid::Cell NearestPointGrid::cell_of(const cv::Vec3f& p) const {
  return {static_cast<int64_t>(std::floor((p[0] - origin_[0]) / cell_mm_)),
          static_cast<int64_t>(std::floor((p[1] - origin_[1]) / cell_mm_)),
          static_cast<int64_t>(std::floor((p[2] - origin_[2]) / cell_mm_))};
}

uint64_t NearestPointGrid::key(int64_t x, int64_t y, int64_t z) {
  // 21 bits per axis (offset so that cells a little outside the box stay distinct).
  constexpr int64_t kOffset = int64_t{1} << 20;
  const auto u = [](int64_t v) { return static_cast<uint64_t>(v + kOffset) & 0x1FFFFF; };
  return u(x) | (u(y) << 21) | (u(z) << 42);
}

int64_t NearestPointGrid::nearest(const cv::Vec3f& p) const {
  if (points_.empty()) return -1;
  const Cell c = cell_of(p);
  double best_d2 = std::numeric_limits<double>::infinity();
  int64_t best = -1;
  auto visit = [&](int64_t x, int64_t y, int64_t z) {
    const auto it = cells_.find(key(x, y, z));
    if (it == cells_.end()) return;
    for (int32_t k = it->second.first; k < it->second.second; ++k) {
      const int32_t i = order_[k];
      const cv::Vec3d d = cv::Vec3d(points_[i]) - cv::Vec3d(p);
      const double d2 = d.dot(d);
      if (d2 < best_d2 || (d2 == best_d2 && i < best)) {
        best_d2 = d2;
        best = i;
      }
    }
  };
  // Cube shells of cells around p's cell, clipped to the cells of the points' box [0, hi_cell_],
  // from the first shell that reaches the box until no unvisited cell can hold a nearer point.
  const int64_t cq[3] = {c.x, c.y, c.z}, hq[3] = {hi_cell_.x, hi_cell_.y, hi_cell_.z};
  int64_t first = 0, last = 0;
  for (int a = 0; a < 3; ++a) {
    first = std::max({first, -cq[a], cq[a] - hq[a]});
    last = std::max({last, std::abs(cq[a]), std::abs(cq[a] - hq[a])});
  }
  for (int64_t r = first; r <= last; ++r) {
    int64_t lo[3], hi[3];  // offsets from p's cell within both the shell's cube and the box
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(-r, -cq[a]);
      hi[a] = std::min(r, hq[a] - cq[a]);
    }
    for (int64_t dz = lo[2]; dz <= hi[2]; ++dz)
      for (int64_t dy = lo[1]; dy <= hi[1]; ++dy) {
        if (std::abs(dz) == r || std::abs(dy) == r) {
          for (int64_t dx = lo[0]; dx <= hi[0]; ++dx) visit(c.x + dx, c.y + dy, c.z + dz);
        } else {  // inside the cube's faces in z and y: only the two x faces are on the shell
          if (-r >= lo[0]) visit(c.x - r, c.y + dy, c.z + dz);
          if (r > 0 && r <= hi[0]) visit(c.x + r, c.y + dy, c.z + dz);
        }
      }
    // Every point in shell r + 1 or beyond is at least r cells away from p.
    if (best >= 0 && std::sqrt(best_d2) <= r * cell_mm_) break;
  }
  return best;
}

}  // namespace gvkit::bench
