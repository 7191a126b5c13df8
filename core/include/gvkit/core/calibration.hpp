#pragma once
// Calibration of a structured-light rig: the camera, and the projector modelled as an inverse
// camera. Pixels are in each device's own image; lengths in millimetres; the camera frame is
// OpenCV's (x right, y down, z forward). cam_from_proj maps projector-frame points into the
// camera frame: X_cam = R_cam_from_proj * X_proj + t_cam_from_proj_mm.

#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/status.hpp"

namespace gvkit {

struct Calibration {
  cv::Matx33d camera_K = cv::Matx33d::eye();
  std::vector<double> camera_dist;  // OpenCV order k1 k2 p1 p2 [k3 ...]; empty = no distortion
  int camera_width = 0, camera_height = 0;  // pixels

  cv::Matx33d projector_K = cv::Matx33d::eye();
  std::vector<double> projector_dist;
  int projector_width = 0, projector_height = 0;  // pixels

  cv::Matx33d R_cam_from_proj = cv::Matx33d::eye();
  cv::Vec3d t_cam_from_proj_mm{0, 0, 0};

  double fringe_pitch_px =
      0;  // projector pixels per fringe period of the finest pattern; 0 = unset

  // Reprojection errors reported by the calibration that produced this (px); negative = unknown.
  double camera_error_px = -1, projector_error_px = -1, stereo_error_px = -1;

  // Inverse of cam_from_proj.
  cv::Matx33d R_proj_from_cam() const { return R_cam_from_proj.t(); }
  cv::Vec3d t_proj_from_cam_mm() const { return -(R_cam_from_proj.t() * t_cam_from_proj_mm); }

  // Baseline length between the two optical centres (mm).
  double baseline_mm() const { return cv::norm(t_cam_from_proj_mm); }

  // Ok when every matrix is finite, focal lengths are positive, sizes are positive, the rotation
  // is orthonormal (to 1e-3) and the baseline is non-zero; else says which field is wrong.
  Status check() const;
};

// The calibration of a camera whose images are `size` instead of camera_width x camera_height
// with the same aspect ratio (binned, downsampled or upsampled images): camera_K scaled with
// pixel centres kept (x' = (x + 0.5) * s - 0.5); lens distortion, which acts on normalized
// coordinates, and the projector are unchanged. Fails when the aspect ratios differ by more
// than 0.5 %.
Result<Calibration> rescale_camera(const Calibration& calibration, cv::Size size);

}  // namespace gvkit
