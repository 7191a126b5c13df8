#include "rasterizer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>

#include "gvkit/capture/lens_distortion.hpp"

namespace gvkit::capture::detail {

cv::Mat pixel_rays(const cv::Matx33d& K, const std::vector<double>& dist, cv::Size size) {
  std::vector<cv::Point2f> pixels, normalized;
  pixels.reserve(size.area());
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      pixels.emplace_back(static_cast<float>(x), static_cast<float>(y));
  cv::undistortPoints(pixels, normalized, K, dist, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 40, 1e-12));
  return cv::Mat(normalized, true).reshape(2, size.height);
}

cv::Point2d project_point(const cv::Vec3d& p, const cv::Matx33d& K,
                          const std::vector<double>& dist) {
  double x = p[0] / p[2], y = p[1] / p[2];
  if (!dist.empty()) {
    LensDistortion lens;
    lens.set(dist);
    double xd, yd;
    lens.apply(x, y, xd, yd);
    x = xd;
    y = yd;
  }
  return {K(0, 0) * x + K(0, 1) * y + K(0, 2), K(1, 1) * y + K(1, 2)};
}

DepthBuffer rasterize(const std::vector<cv::Vec3d>& points_mm,
                      const std::vector<cv::Vec3i>& triangles, const cv::Mat& rays,
                      const cv::Matx33d& K, const std::vector<double>& dist) {
  const int w = rays.cols, h = rays.rows;
  DepthBuffer out;
  out.depth = cv::Mat(h, w, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));
  out.triangle = cv::Mat(h, w, CV_32S, cv::Scalar(-1));
  out.barycentric = cv::Mat(h, w, CV_32FC3, cv::Scalar::all(0));
  LensDistortion lens;
  lens.set(dist);
  const double margin = lens.none ? 1.0 : 2.5;
  // Project every vertex once.
  std::vector<cv::Point2d> pixel(points_mm.size()), norm(points_mm.size());
  for (size_t i = 0; i < points_mm.size(); ++i) {
    const cv::Vec3d& p = points_mm[i];
    if (p[2] <= 1.0) {
      pixel[i] = {NAN, NAN};
      continue;
    }
    norm[i] = {p[0] / p[2], p[1] / p[2]};
    double xd = norm[i].x, yd = norm[i].y;
    if (!lens.none) lens.apply(norm[i].x, norm[i].y, xd, yd);
    pixel[i] = {K(0, 0) * xd + K(0, 1) * yd + K(0, 2), K(1, 1) * yd + K(1, 2)};
  }
  for (size_t t = 0; t < triangles.size(); ++t) {
    const cv::Vec3i& tri = triangles[t];
    const cv::Point2d &p0 = pixel[tri[0]], &p1 = pixel[tri[1]], &p2 = pixel[tri[2]];
    if (!(std::isfinite(p0.x) && std::isfinite(p1.x) && std::isfinite(p2.x))) continue;
    // Pixel box, clamped in floating point first (vertices near the camera plane project far).
    auto to_index = [](double v, int size) {
      return static_cast<int>(std::clamp(v, -1.0, static_cast<double>(size)));
    };
    const int x0 = std::max(0, to_index(std::floor(std::min({p0.x, p1.x, p2.x}) - margin), w));
    const int x1 = std::min(w - 1, to_index(std::ceil(std::max({p0.x, p1.x, p2.x}) + margin), w));
    const int y0 = std::max(0, to_index(std::floor(std::min({p0.y, p1.y, p2.y}) - margin), h));
    const int y1 = std::min(h - 1, to_index(std::ceil(std::max({p0.y, p1.y, p2.y}) + margin), h));
    if (x0 > x1 || y0 > y1) continue;
    // Edge functions in the normalized plane.
    const cv::Point2d &a = norm[tri[0]], &b = norm[tri[1]], &c = norm[tri[2]];
    const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (std::abs(area) < 1e-14) continue;
    const double inv_area = 1.0 / area;
    const double iz0 = 1.0 / points_mm[tri[0]][2], iz1 = 1.0 / points_mm[tri[1]][2],
                 iz2 = 1.0 / points_mm[tri[2]][2];
    for (int y = y0; y <= y1; ++y) {
      const cv::Vec2f* ray = rays.ptr<cv::Vec2f>(y);
      float* depth = out.depth.ptr<float>(y);
      int* id = out.triangle.ptr<int>(y);
      cv::Vec3f* bary = out.barycentric.ptr<cv::Vec3f>(y);
      for (int x = x0; x <= x1; ++x) {
        const double px = ray[x][0], py = ray[x][1];
        const double w0 = ((b.x - px) * (c.y - py) - (b.y - py) * (c.x - px)) * inv_area;
        const double w1 = ((c.x - px) * (a.y - py) - (c.y - py) * (a.x - px)) * inv_area;
        const double w2 = 1.0 - w0 - w1;
        if (w0 < -1e-9 || w1 < -1e-9 || w2 < -1e-9) continue;
        // Perspective-correct: 1/z is affine in the normalized plane.
        const double inv_z = w0 * iz0 + w1 * iz1 + w2 * iz2;
        const double z = 1.0 / inv_z;
        if (z >= depth[x]) continue;
        depth[x] = static_cast<float>(z);
        id[x] = static_cast<int>(t);
        bary[x] = cv::Vec3f(static_cast<float>(w0 * iz0 * z), static_cast<float>(w1 * iz1 * z),
                            static_cast<float>(w2 * iz2 * z));
      }
    }
  }
  return out;
}

}  // namespace gvkit::capture::detail
