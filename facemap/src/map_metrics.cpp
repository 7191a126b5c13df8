#include "gvkit/facemap/map_metrics.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace gvkit::facemap {

MapQuality measure_map_quality(const std::vector<Eigen::Vector3d>& xyz,
                               const std::vector<Eigen::Vector2d>& uv, int orientation) {
  GVKIT_CHECK(xyz.size() == uv.size() && xyz.size() % 3 == 0);
  MapQuality q;
  q.triangles = static_cast<int>(xyz.size() / 3);
  // The singular values s1, s2 of a triangle's Jacobian J (uv with respect to the triangle's own
  // 2D frame) enter the measures only as s1 s2 = |det J| and s1^2 + s2^2 = |J|_F^2, so no SVD:
  // s1 / s2 + s2 / s1 = |J|_F^2 / |det J|. |det J| is the ratio of the areas (uv over 3D).
  struct Tri {
    double area3d;
    double det;         // |det J|
    double frobenius2;  // |J|_F^2
  };
  std::vector<Tri> good;
  double total3d = 0, total_uv = 0;
  for (int k = 0; k < q.triangles; ++k) {
    const Eigen::Vector3d& p0 = xyz[3 * k];
    const Eigen::Vector2d& u0 = uv[3 * k];
    if (!u0.allFinite() || !uv[3 * k + 1].allFinite() || !uv[3 * k + 2].allFinite()) {
      ++q.unmapped;
      continue;
    }
    const Eigen::Vector2d du1 = uv[3 * k + 1] - u0, du2 = uv[3 * k + 2] - u0;
    const double signed_uv = 0.5 * (du1.x() * du2.y() - du1.y() * du2.x()) * orientation;
    if (!(signed_uv > 0)) {
      ++q.flipped;
      continue;
    }
    const Eigen::Vector3d e1 = xyz[3 * k + 1] - p0, e2 = xyz[3 * k + 2] - p0;
    const double len1 = e1.norm();
    const Eigen::Vector3d n = e1.cross(e2);
    const double area = 0.5 * n.norm();
    if (!(area > 0) || !(len1 > 0)) continue;
    const Eigen::Vector3d ax = e1 / len1, ay = n.normalized().cross(ax);
    Eigen::Matrix2d x;  // columns: e1, e2 in the local frame
    x << len1, e2.dot(ax), 0, e2.dot(ay);
    Eigen::Matrix2d u;
    u << du1.x(), du2.x(), du1.y(), du2.y();
    good.push_back({area, signed_uv / area, (u * x.inverse()).squaredNorm()});
    total3d += area;
    total_uv += signed_uv;
  }
  if (good.empty() || !(total_uv > 0)) return q;
  // uv -> mm so that the areas agree: J scaled by `scale`, its determinant by scale^2.
  const double scale2 = total3d / total_uv;
  double angle = 0, area_d = 0;
  for (const Tri& t : good) {
    const double det = std::max(t.det * scale2, 1e-300);
    angle += t.area3d * 0.5 * (t.frobenius2 * scale2 / det);
    area_d += t.area3d * 0.5 * (det + 1.0 / det);
  }
  q.eps_angle = angle / total3d;
  q.eps_area = area_d / total3d;
  return q;
}

namespace {

DriftStats summarize(const std::vector<double>& d) {
  DriftStats s;
  s.count = static_cast<int>(d.size());
  if (d.empty()) return s;
  double sum = 0, sum2 = 0;
  for (double x : d) sum += x, sum2 += x * x, s.max = std::max(s.max, x);
  s.mean = sum / s.count;
  s.rms = std::sqrt(sum2 / s.count);
  return s;
}

}  // namespace

DriftStats feature_drift(const std::vector<Eigen::Vector2d>& a,
                         const std::vector<Eigen::Vector2d>& b, const std::vector<int>& indices) {
  std::vector<double> d;
  for (int i : indices) {
    if (i < 0 || i >= static_cast<int>(a.size()) || i >= static_cast<int>(b.size())) continue;
    if (!a[i].allFinite() || !b[i].allFinite()) continue;
    d.push_back((a[i] - b[i]).norm());
  }
  return summarize(d);
}

namespace {

// The point with weights w of the frame whose vertex positions are positions_mm.
cv::Vec3d weighted_point(const SourceWeights& w, const std::vector<cv::Vec3d>& positions_mm) {
  cv::Vec3d p(0, 0, 0);
  for (const auto& s : w) {
    GVKIT_CHECK(s.vertex >= 0 && s.vertex < static_cast<int>(positions_mm.size()),
                "correspondence needs the same vertex indices in both frames");
    p += s.weight * positions_mm[s.vertex];
  }
  return p;
}

}  // namespace

DriftStats true_surface_drift(const MappedFace& a, const MappedFace& b,
                              const std::vector<cv::Vec3d>& positions_b_mm) {
  GVKIT_CHECK(a.pixel_source.size() == b.pixel_source.size(), "same domain size");
  std::vector<double> d;
  for (size_t i = 0; i < a.pixel_source.size(); ++i) {
    if (a.pixel_source[i].empty() || b.pixel_source[i].empty()) continue;
    d.push_back(cv::norm(weighted_point(a.pixel_source[i], positions_b_mm) -
                         weighted_point(b.pixel_source[i], positions_b_mm)));
  }
  return summarize(d);
}

GeometryImage carried_geometry_image(const MappedFace& a,
                                     const std::vector<cv::Vec3d>& positions_b_mm) {
  const cv::Size size = a.image.size();
  GVKIT_CHECK(a.pixel_source.size() == static_cast<size_t>(size.area()),
              "one pixel source per pixel");
  GeometryImage out;
  out.xyz_mm = cv::Mat(size, CV_32FC3, cv::Scalar::all(0));
  out.domain_mask = a.image.domain_mask.clone();
  out.index = a.image.index;
  out.timestamp = a.image.timestamp;
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const SourceWeights& w = a.pixel_source[static_cast<size_t>(y) * size.width + x];
      if (w.empty()) {  // a pixel filled from its neighbours has no sample to carry
        out.domain_mask.at<uint8_t>(y, x) = 0;
        continue;
      }
      out.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(weighted_point(w, positions_b_mm));
    }
  return out;
}

}  // namespace gvkit::facemap
