#include "gvkit/facemap/synthetic_face_scan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "triangle_raster.hpp"

namespace gvkit::facemap {

namespace {

double albedo_of(IctRegion region) {
  switch (region) {
    case IctRegion::kSclera:
      return 0.92;
    case IctRegion::kIris:
      return 0.12;
    case IctRegion::kMouthSocket:
    case IctRegion::kGumsAndTongue:
      return 0.2;
    case IctRegion::kTeeth:
      return 0.85;
    default:
      return 0.68;
  }
}

bool rendered(IctRegion region) {
  return region != IctRegion::kEyeExtras && region != IctRegion::kEyelashes &&
         region != IctRegion::kEyeSocket;
}

// Distance from p to segment ab (2D, model x/y).
double segment_distance(const cv::Vec2d& p, const cv::Vec2d& a, const cv::Vec2d& b) {
  const cv::Vec2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.dot(ab), 1e-12), 0.0, 1.0);
  return cv::norm(p - (a + t * ab));
}

bool inside_polygon(const cv::Vec2d& p, const std::vector<cv::Vec2d>& poly) {
  bool inside = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++)
    if ((poly[i][1] > p[1]) != (poly[j][1] > p[1]) &&
        p[0] < (poly[j][0] - poly[i][0]) * (p[1] - poly[i][1]) / (poly[j][1] - poly[i][1]) +
                   poly[i][0])
      inside = !inside;
  return inside;
}

}  // namespace

std::vector<double> ict_vertex_albedo(const IctFaceModel& model,
                                      const std::vector<cv::Vec3d>& positions_mm) {
  const auto& lm = model.landmark_vertices();
  // Per-vertex albedo: by region, then lips and brows from the landmark contours.
  std::vector<cv::Vec2d> lips;
  for (int i = 48; i < 60; ++i) lips.emplace_back(positions_mm[lm[i]][0], positions_mm[lm[i]][1]);
  std::vector<double> albedo(positions_mm.size());
  for (size_t v = 0; v < positions_mm.size(); ++v) {
    const IctRegion region = IctFaceModel::region_of(static_cast<int>(v));
    albedo[v] = albedo_of(region);
    if (region != IctRegion::kFace) continue;
    const cv::Vec2d p(positions_mm[v][0], positions_mm[v][1]);
    if (inside_polygon(p, lips)) albedo[v] = 0.42;
    for (int i = 17; i < 26; ++i) {
      if (i == 21) continue;  // the two brows are separate
      const cv::Vec2d a(positions_mm[lm[i]][0], positions_mm[lm[i]][1]);
      const cv::Vec2d b(positions_mm[lm[i + 1]][0], positions_mm[lm[i + 1]][1]);
      if (segment_distance(p, a, b) < 3.0 &&
          std::abs(positions_mm[v][2] - positions_mm[lm[i]][2]) < 10)
        albedo[v] = 0.25;
    }
  }
  return albedo;
}

SyntheticFaceScan render_synthetic_face_scan(const IctFaceModel& model,
                                             const std::vector<cv::Vec3d>& positions_mm,
                                             const SyntheticFaceScanOptions& options) {
  const int n = options.size_px;
  const double s = options.pixel_mm;
  const auto& lm = model.landmark_vertices();
  // Image centre on the middle of the landmarks (x) and between brows and chin (y).
  cv::Vec3d center(0, 0, 0);
  for (int v : lm) center += positions_mm[v];
  center /= 68.0;
  auto to_camera = [&](const cv::Vec3d& p) {
    return cv::Vec3d(p[0] - center[0], -(p[1] - center[1]), options.distance_mm - p[2]);
  };
  auto to_pixel = [&](const cv::Vec3d& c) {
    return cv::Vec2d(c[0] / s + (n - 1) / 2.0, c[1] / s + (n - 1) / 2.0);
  };

  const std::vector<double> albedo = ict_vertex_albedo(model, positions_mm);

  SyntheticFaceScan out;
  RangeScan& scan = out.scan;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  scan.xyz_mm = cv::Mat(n, n, CV_32FC3, cv::Scalar(nan, nan, nan));
  scan.texture = cv::Mat(n, n, CV_32F, cv::Scalar(0.05f));
  scan.valid = cv::Mat(n, n, CV_8U, cv::Scalar(0));
  scan.quality = cv::Mat(n, n, CV_32F, cv::Scalar(0.0f));
  cv::Mat depth(n, n, CV_64F, cv::Scalar(std::numeric_limits<double>::infinity()));
  cv::Vec3d light = options.light / cv::norm(options.light);

  for (const auto& polygon : model.polygons()) {
    for (size_t k = 1; k + 1 < polygon.size(); ++k) {
      const int vi[3] = {polygon[0].vertex, polygon[k].vertex, polygon[k + 1].vertex};
      const IctRegion region = IctFaceModel::region_of(vi[0]);
      if (!rendered(region)) continue;
      cv::Vec3d c[3];
      cv::Vec2d px[3];
      for (int j = 0; j < 3; ++j) {
        c[j] = to_camera(positions_mm[vi[j]]);
        px[j] = to_pixel(c[j]);
      }
      // Lambert shading from the (model frame) face normal.
      const cv::Vec3d& p0 = positions_mm[vi[0]];
      cv::Vec3d normal = (positions_mm[vi[1]] - p0).cross(positions_mm[vi[2]] - p0);
      normal /= std::max(cv::norm(normal), 1e-12);
      const double shade = 0.3 + 0.7 * std::max(0.0, std::abs(normal.dot(light)));
      const bool skin = region == IctRegion::kFace || region == IctRegion::kHeadAndNeck;
      rasterize_triangle(px, n, n, [&](int x, int y, const double(&w)[3]) {
        const cv::Vec3d p = w[0] * c[0] + w[1] * c[1] + w[2] * c[2];
        if (p[2] >= depth.at<double>(y, x)) return;
        depth.at<double>(y, x) = p[2];
        const double a = w[0] * albedo[vi[0]] + w[1] * albedo[vi[1]] + w[2] * albedo[vi[2]];
        scan.texture.at<float>(y, x) = static_cast<float>(std::clamp(a * shade, 0.0, 1.0));
        if (skin) {
          scan.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(p);
          scan.valid.at<uint8_t>(y, x) = 255;
          scan.quality.at<float>(y, x) = 1.0f;
        } else {
          scan.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(nan, nan, nan);
          scan.valid.at<uint8_t>(y, x) = 0;
          scan.quality.at<float>(y, x) = 0.0f;
        }
      });
    }
  }
  for (int v : lm) {
    const cv::Vec3d c = to_camera(positions_mm[v]);
    const cv::Vec2d p = to_pixel(c);
    out.landmarks.points_px.emplace_back(static_cast<float>(p[0]), static_cast<float>(p[1]));
    out.landmarks.points_mm.emplace_back(c);
  }
  return out;
}

}  // namespace gvkit::facemap
