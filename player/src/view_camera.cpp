#include "gvkit/player/view_camera.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace gvkit::player {
namespace {

constexpr double kPi = 3.14159265358979323846;
double radians(double deg) { return deg * kPi / 180.0; }

}  // namespace

SceneFrame scene_frame(const MeshBuffers& mesh) {
  SceneFrame f;
  const size_t n = mesh.vertex_count();
  if (n == 0) return f;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p(mesh.positions_mm[3 * i], mesh.positions_mm[3 * i + 1],
                            mesh.positions_mm[3 * i + 2]);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    normal_sum +=
        Eigen::Vector3d(mesh.normals[3 * i], mesh.normals[3 * i + 1], mesh.normals[3 * i + 2]);
  }
  f.center_mm = 0.5 * (lo + hi);
  f.radius_mm = std::max(0.5 * (hi - lo).norm(), 1e-3);
  Eigen::Vector3d facing =
      normal_sum.norm() > 1e-9 ? normal_sum.normalized() : Eigen::Vector3d(0, 0, -1);

  // Which side is the front: a surface that bulges towards the viewer (a face) has normals that
  // diverge on that side, so sum (p - mean) . n is positive when the normals point at the
  // viewer (for a closed surface with outward normals it is 3 x volume). Flat: keep the mean.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i)
    mean += Eigen::Vector3d(mesh.positions_mm[3 * i], mesh.positions_mm[3 * i + 1],
                            mesh.positions_mm[3 * i + 2]);
  mean /= static_cast<double>(n);
  double divergence = 0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p(mesh.positions_mm[3 * i], mesh.positions_mm[3 * i + 1],
                            mesh.positions_mm[3 * i + 2]);
    divergence += (p - mean).dot(
        Eigen::Vector3d(mesh.normals[3 * i], mesh.normals[3 * i + 1], mesh.normals[3 * i + 2]));
  }
  if (divergence < -1e-3 * f.radius_mm * static_cast<double>(n)) facing = -facing;
  f.facing = facing;

  Eigen::Vector3d right = Eigen::Vector3d::UnitX() - facing.x() * facing;
  if (right.norm() < 1e-6) right = Eigen::Vector3d::UnitY() - facing.y() * facing;
  f.right = right.normalized();
  f.up = facing.cross(f.right).normalized();
  return f;
}

Result<ViewPreset> parse_view_preset(const std::string& name) {
  if (name == "front") return ViewPreset::kFront;
  if (name == "left") return ViewPreset::kLeft;
  if (name == "right") return ViewPreset::kRight;
  if (name == "orbit") return ViewPreset::kOrbit;
  return invalid_argument("unknown view '" + name + "' (use front, left, right or orbit)");
}

void ViewCamera::reset() {
  yaw_ = pitch_ = 0;
  zoom_ = 1;
  pan_.setZero();
}

void ViewCamera::set_preset(ViewPreset preset, double phase) {
  reset();
  switch (preset) {
    case ViewPreset::kFront:
      break;
    case ViewPreset::kLeft:
      yaw_ = -radians(50);
      break;
    case ViewPreset::kRight:
      yaw_ = radians(50);
      break;
    case ViewPreset::kOrbit:
      yaw_ = radians(60) * std::sin(2 * kPi * phase);
      break;
  }
}

void ViewCamera::orbit(double d_yaw, double d_pitch) {
  yaw_ += d_yaw;
  pitch_ = std::clamp(pitch_ + d_pitch, -radians(85), radians(85));
}

void ViewCamera::pan(double dx, double dy) { pan_ += Eigen::Vector2d(dx, dy) * zoom_; }

void ViewCamera::zoom(double factor) {
  GVKIT_CHECK(factor > 0, "zoom factor must be > 0");
  zoom_ = std::clamp(zoom_ * factor, 0.02, 50.0);
}

Eigen::Vector3d ViewCamera::direction() const {
  return std::cos(pitch_) * (std::cos(yaw_) * frame_.facing + std::sin(yaw_) * frame_.right) +
         std::sin(pitch_) * frame_.up;
}

Eigen::Vector3d ViewCamera::pan_offset_mm() const {
  // Pan moves along the current view's right and up axes.
  const Eigen::Vector3d dir = direction();
  Eigen::Vector3d right = frame_.up.cross(dir);
  if (right.norm() < 1e-9) right = frame_.right;
  right.normalize();
  const Eigen::Vector3d up = dir.cross(right);
  return frame_.radius_mm * (pan_.x() * right + pan_.y() * up);
}

Eigen::Vector3d ViewCamera::target_mm() const { return frame_.center_mm + pan_offset_mm(); }

Eigen::Vector3d ViewCamera::eye_mm() const {
  const double distance = frame_.radius_mm / std::sin(radians(fov_y_deg) / 2) * 1.05 * zoom_;
  return target_mm() + distance * direction();
}

Eigen::Matrix4f ViewCamera::view_from_world() const {
  const Eigen::Vector3d eye = eye_mm();
  const Eigen::Vector3d target = target_mm();
  const Eigen::Vector3d back = (eye - target).normalized();  // view +z
  Eigen::Vector3d right = frame_.up.cross(back);
  if (right.norm() < 1e-9) right = frame_.right;
  right.normalize();
  const Eigen::Vector3d up = back.cross(right);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<1, 3>(0, 0) = right.transpose();
  m.block<1, 3>(1, 0) = up.transpose();
  m.block<1, 3>(2, 0) = back.transpose();
  m(0, 3) = -right.dot(eye);
  m(1, 3) = -up.dot(eye);
  m(2, 3) = -back.dot(eye);
  return m.cast<float>();
}

Eigen::Matrix4f ViewCamera::clip_from_view(double aspect) const {
  GVKIT_CHECK(aspect > 0, "aspect must be > 0");
  const double distance = (eye_mm() - target_mm()).norm();
  const double near_mm = std::max(distance - 3 * frame_.radius_mm, distance * 0.01);
  const double far_mm = distance + 3 * frame_.radius_mm;
  const double f = 1.0 / std::tan(radians(fov_y_deg) / 2);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = f / aspect;
  p(1, 1) = f;
  p(2, 2) = (far_mm + near_mm) / (near_mm - far_mm);
  p(2, 3) = 2 * far_mm * near_mm / (near_mm - far_mm);
  p(3, 2) = -1;
  return p.cast<float>();
}

}  // namespace gvkit::player
