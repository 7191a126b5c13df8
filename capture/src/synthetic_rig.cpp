#include "gvkit/capture/synthetic_rig.hpp"

#include <cmath>

#include <nlohmann/json.hpp>

namespace gvkit::capture {

nlohmann::json SyntheticRigOptions::to_json() const {
  return {{"camera_hfov_deg", camera_hfov_deg},
          {"projector_size", {projector_width, projector_height}},
          {"projector_focal_px", projector_focal_px},
          {"baseline_mm", baseline_mm},
          {"axes_cross_mm", axes_cross_mm}};
}

Status SyntheticRigOptions::check() const {
  if (camera_width < 8 || camera_height < 8 || camera_width > 8192 || camera_height > 8192)
    return invalid_argument("camera size must be 8..8192 px per side");
  if (!(camera_hfov_deg > 1 && camera_hfov_deg < 170))
    return invalid_argument("camera field of view must be in (1, 170) degrees");
  if (projector_width < 8 || projector_height < 8 || projector_width > 8192 ||
      projector_height > 8192)
    return invalid_argument("projector size must be 8..8192 px per side");
  if (!(projector_focal_px > 0)) return invalid_argument("projector focal length must be > 0");
  if (!(baseline_mm > 0)) return invalid_argument("baseline must be > 0 mm");
  if (!(axes_cross_mm > 0)) return invalid_argument("axes crossing distance must be > 0 mm");
  return Status::ok();
}

Calibration synthetic_calibration(const SyntheticRigOptions& o) {
  Calibration c;
  const double f = 0.5 * o.camera_width / std::tan(0.5 * o.camera_hfov_deg * CV_PI / 180.0);
  c.camera_K =
      cv::Matx33d(f, 0, 0.5 * (o.camera_width - 1), 0, f, 0.5 * (o.camera_height - 1), 0, 0, 1);
  c.camera_dist = o.camera_dist;
  c.camera_width = o.camera_width;
  c.camera_height = o.camera_height;
  const double fp = o.projector_focal_px;
  c.projector_K = cv::Matx33d(fp, 0, 0.5 * (o.projector_width - 1), 0, fp,
                              0.5 * (o.projector_height - 1), 0, 0, 1);
  c.projector_dist = o.projector_dist;
  c.projector_width = o.projector_width;
  c.projector_height = o.projector_height;
  // Projector axes in camera coordinates: z towards (0, 0, cross), y along the camera's y.
  const cv::Vec3d z = cv::normalize(cv::Vec3d(-o.baseline_mm, 0, o.axes_cross_mm));
  const cv::Vec3d y(0, 1, 0);
  const cv::Vec3d x = y.cross(z);
  c.R_cam_from_proj = cv::Matx33d(x[0], y[0], z[0], x[1], y[1], z[1], x[2], y[2], z[2]);
  c.t_cam_from_proj_mm = cv::Vec3d(o.baseline_mm, 0, 0);
  return c;
}

}  // namespace gvkit::capture
