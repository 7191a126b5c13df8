#include "gvkit/facemap/map_metrics.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace gvkit::facemap {
namespace {

// The distortion measures by their definition: the singular values of each triangle's Jacobian
// (uv scaled to the 3D area, with respect to the triangle's own frame) by an SVD.
void distortion_by_svd(const std::vector<Eigen::Vector3d>& xyz,
                       const std::vector<Eigen::Vector2d>& uv, int orientation, double* eps_angle,
                       double* eps_area) {
  std::vector<std::pair<double, Eigen::Matrix2d>> jacobians;
  double total3d = 0, total_uv = 0;
  for (size_t k = 0; 3 * k < xyz.size(); ++k) {
    const Eigen::Vector2d du1 = uv[3 * k + 1] - uv[3 * k], du2 = uv[3 * k + 2] - uv[3 * k];
    const double signed_uv = 0.5 * (du1.x() * du2.y() - du1.y() * du2.x()) * orientation;
    const Eigen::Vector3d e1 = xyz[3 * k + 1] - xyz[3 * k], e2 = xyz[3 * k + 2] - xyz[3 * k];
    const Eigen::Vector3d n = e1.cross(e2);
    const Eigen::Vector3d ax = e1.normalized(), ay = n.normalized().cross(ax);
    Eigen::Matrix2d x, u;
    x << e1.norm(), e2.dot(ax), 0, e2.dot(ay);
    u << du1.x(), du2.x(), du1.y(), du2.y();
    jacobians.emplace_back(0.5 * n.norm(), u * x.inverse());
    total3d += 0.5 * n.norm();
    total_uv += signed_uv;
  }
  const double scale = std::sqrt(total3d / total_uv);
  double angle = 0, area = 0;
  for (const auto& [a, j] : jacobians) {
    Eigen::JacobiSVD<Eigen::Matrix2d> svd(j * scale);
    const double s1 = svd.singularValues()[0], s2 = svd.singularValues()[1];
    angle += a * 0.5 * (s1 / s2 + s2 / s1);
    area += a * 0.5 * (s1 * s2 + 1.0 / (s1 * s2));
  }
  *eps_angle = angle / total3d;
  *eps_area = area / total3d;
}

// Random triangles in 3D mapped by random linear maps (anisotropic ones and slivers included),
// both orientations: the measures equal the SVD's.
TEST(MapMetrics, DistortionEqualsTheSingularValuesDefinition) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const int orientation = trial % 2 ? 1 : -1;
    std::vector<Eigen::Vector3d> xyz;
    std::vector<Eigen::Vector2d> uv;
    for (int k = 0; k < 200; ++k) {
      Eigen::Vector3d p0(unit(rng), unit(rng), unit(rng));
      Eigen::Vector3d p1 = p0 + Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
      Eigen::Vector3d p2 = p0 + Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
      if (k % 10 == 0) p2 = p0 + 0.5 * (p1 - p0) + 1e-4 * Eigen::Vector3d::UnitZ();  // a sliver
      // uv: the triangle's own coordinates under a random linear map with positive determinant
      // (in the given orientation).
      const Eigen::Vector3d ax = (p1 - p0).normalized();
      const Eigen::Vector3d ay = (p1 - p0).cross(p2 - p0).normalized().cross(ax);
      Eigen::Matrix2d m;
      m << 1 + unit(rng), unit(rng), unit(rng), (k % 7 == 0 ? 20.0 : 1.0) + unit(rng);
      if (m.determinant() < 0) m.col(0) *= -1;
      if (orientation < 0) m.row(1) *= -1;
      for (const Eigen::Vector3d& p : {p0, p1, p2}) {
        xyz.push_back(p);
        uv.push_back(m * Eigen::Vector2d((p - p0).dot(ax), (p - p0).dot(ay)) * 37.0);
      }
    }
    const MapQuality q = measure_map_quality(xyz, uv, orientation);
    ASSERT_EQ(q.flipped, 0) << "trial " << trial;
    double eps_angle = 0, eps_area = 0;
    distortion_by_svd(xyz, uv, orientation, &eps_angle, &eps_area);
    EXPECT_NEAR(q.eps_angle, eps_angle, 1e-9 * eps_angle) << "trial " << trial;
    EXPECT_NEAR(q.eps_area, eps_area, 1e-9 * eps_area) << "trial " << trial;
    EXPECT_GT(q.eps_angle, 1.0);
  }
}

}  // namespace
}  // namespace gvkit::facemap
