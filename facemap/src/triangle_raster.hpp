#pragma once
// Scan conversion of one 2D triangle on a pixel grid, shared by facemap's small software renders
// (the frontal render for mesh landmarks, the synthetic face scan).

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

namespace gvkit::facemap {

// Calls visit(x, y, w) for every integer pixel position (x, y) of a cols x rows grid that lies
// inside the triangle px (pixel coordinates, either winding), with w its barycentric weights
// (w[j] belongs to px[j], sum 1). A degenerate triangle (|area| < 1e-12 px^2) visits nothing.
template <class Visit>
void rasterize_triangle(const cv::Vec2d (&px)[3], int cols, int rows, Visit&& visit) {
  const double area =
      (px[1][0] - px[0][0]) * (px[2][1] - px[0][1]) - (px[2][0] - px[0][0]) * (px[1][1] - px[0][1]);
  if (std::abs(area) < 1e-12) return;
  const int x0 =
      std::max(0, static_cast<int>(std::floor(std::min({px[0][0], px[1][0], px[2][0]}))));
  const int x1 =
      std::min(cols - 1, static_cast<int>(std::ceil(std::max({px[0][0], px[1][0], px[2][0]}))));
  const int y0 =
      std::max(0, static_cast<int>(std::floor(std::min({px[0][1], px[1][1], px[2][1]}))));
  const int y1 =
      std::min(rows - 1, static_cast<int>(std::ceil(std::max({px[0][1], px[1][1], px[2][1]}))));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      double w[3];
      for (int j = 0; j < 3; ++j) {
        const cv::Vec2d& a = px[(j + 1) % 3];
        const cv::Vec2d& b = px[(j + 2) % 3];
        w[j] = ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) / area;
      }
      if (w[0] < -1e-9 || w[1] < -1e-9 || w[2] < -1e-9) continue;
      visit(x, y, w);
    }
}

}  // namespace gvkit::facemap
