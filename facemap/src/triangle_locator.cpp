#include "gvkit/facemap/triangle_locator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gvkit::facemap {

TriangleLocator::TriangleLocator(std::vector<Eigen::Vector2d> corners, int bins_per_side)
    : corners_(std::move(corners)) {
  const int n = n_triangles();
  lo_ = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  hi_ = -lo_;
  for (const auto& c : corners_) lo_ = lo_.cwiseMin(c), hi_ = hi_.cwiseMax(c);
  if (n == 0) return;
  const int side =
      bins_per_side > 0 ? bins_per_side : std::max(1, static_cast<int>(std::sqrt(double(n)) / 2));
  nx_ = ny_ = side;
  const Eigen::Vector2d extent = (hi_ - lo_).cwiseMax(1e-300);
  auto bin_range = [&](int k, int& x0, int& x1, int& y0, int& y1) {
    Eigen::Vector2d a = corners_[3 * k], b = a;
    for (int j = 1; j < 3; ++j)
      a = a.cwiseMin(corners_[3 * k + j]), b = b.cwiseMax(corners_[3 * k + j]);
    x0 = std::clamp(static_cast<int>((a.x() - lo_.x()) / extent.x() * nx_), 0, nx_ - 1);
    x1 = std::clamp(static_cast<int>((b.x() - lo_.x()) / extent.x() * nx_), 0, nx_ - 1);
    y0 = std::clamp(static_cast<int>((a.y() - lo_.y()) / extent.y() * ny_), 0, ny_ - 1);
    y1 = std::clamp(static_cast<int>((b.y() - lo_.y()) / extent.y() * ny_), 0, ny_ - 1);
  };
  std::vector<int> count(nx_ * ny_ + 1, 0);
  for (int k = 0; k < n; ++k) {
    int x0, x1, y0, y1;
    bin_range(k, x0, x1, y0, y1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) ++count[y * nx_ + x + 1];
  }
  for (size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
  bin_start_ = count;
  bin_items_.resize(count.back());
  for (int k = 0; k < n; ++k) {
    int x0, x1, y0, y1;
    bin_range(k, x0, x1, y0, y1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) bin_items_[count[y * nx_ + x]++] = k;
  }
}

TriangleLocator::Hit TriangleLocator::locate(const Eigen::Vector2d& p, double tolerance) const {
  Hit best;
  if (n_triangles() == 0) return best;
  const Eigen::Vector2d extent = (hi_ - lo_).cwiseMax(1e-300);
  const double fx = (p.x() - lo_.x()) / extent.x() * nx_, fy = (p.y() - lo_.y()) / extent.y() * ny_;
  if (fx < -1e-9 * nx_ || fy < -1e-9 * ny_ || fx > nx_ * (1 + 1e-9) || fy > ny_ * (1 + 1e-9))
    return best;
  const int bx = std::clamp(static_cast<int>(fx), 0, nx_ - 1);
  const int by = std::clamp(static_cast<int>(fy), 0, ny_ - 1);
  double best_min = -tolerance;
  const int bin = by * nx_ + bx;
  for (int i = bin_start_[bin]; i < bin_start_[bin + 1]; ++i) {
    const Hit hit = in_triangle(bin_items_[i], p);
    if (hit.triangle < 0) continue;
    const double mn = std::min({hit.barycentric[0], hit.barycentric[1], hit.barycentric[2]});
    if (mn >= best_min) {
      best_min = mn;
      best = hit;
      if (mn > 0) break;
    }
  }
  return best;
}

TriangleLocator::Hit TriangleLocator::in_triangle(int k, const Eigen::Vector2d& p) const {
  Hit hit;
  const Eigen::Vector2d& a = corners_[3 * k];
  const Eigen::Vector2d& b = corners_[3 * k + 1];
  const Eigen::Vector2d& c = corners_[3 * k + 2];
  const double det = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  if (det == 0) return hit;
  const double l1 = ((p - a).x() * (c - a).y() - (p - a).y() * (c - a).x()) / det;
  const double l2 = ((b - a).x() * (p - a).y() - (b - a).y() * (p - a).x()) / det;
  hit.triangle = k;
  hit.barycentric = {1.0 - l1 - l2, l1, l2};
  return hit;
}

}  // namespace gvkit::facemap
