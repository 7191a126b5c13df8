#include "gvkit/core/calibration.hpp"

#include <cmath>
#include <string>

namespace gvkit {

Result<Calibration> rescale_camera(const Calibration& calibration, cv::Size size) {
  const auto text = [](int w, int h) { return std::to_string(w) + "x" + std::to_string(h); };
  if (size.width <= 0 || size.height <= 0 || calibration.camera_width <= 0 ||
      calibration.camera_height <= 0)
    return invalid_argument("cannot rescale the camera calibration from " +
                            text(calibration.camera_width, calibration.camera_height) + " to " +
                            text(size.width, size.height));
  const double sx = static_cast<double>(size.width) / calibration.camera_width;
  const double sy = static_cast<double>(size.height) / calibration.camera_height;
  if (std::abs(sx / sy - 1) > 0.005)
    return invalid_argument("cannot rescale the camera calibration from " +
                            text(calibration.camera_width, calibration.camera_height) + " to " +
                            text(size.width, size.height) + ": the aspect ratios differ");
  Calibration out = calibration;
  cv::Matx33d& K = out.camera_K;
  K(0, 0) *= sx;
  K(0, 1) *= sx;
  K(0, 2) = (K(0, 2) + 0.5) * sx - 0.5;
  K(1, 1) *= sy;
  K(1, 2) = (K(1, 2) + 0.5) * sy - 0.5;
  out.camera_width = size.width;
  out.camera_height = size.height;
  return out;
}

}  // namespace gvkit
