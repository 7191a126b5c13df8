// check() of the core value types.
#include <cmath>
#include <string>

#include <opencv2/core.hpp>

#include "gvkit/core/calibration.hpp"
#include "gvkit/core/fringe_set.hpp"
#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/range_scan.hpp"

namespace gvkit {
namespace {

std::string size_text(cv::Size s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

template <int M, int N>
bool all_finite(const cv::Matx<double, M, N>& m) {
  for (int i = 0; i < M * N; ++i)
    if (!std::isfinite(m.val[i])) return false;
  return true;
}

bool all_finite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

Status check_intrinsics(const char* name, const cv::Matx33d& K, const std::vector<double>& dist,
                        int width, int height) {
  std::string n = name;
  if (!all_finite(K)) return corrupt_data(n + " matrix has non-finite entries");
  if (!(K(0, 0) > 0 && K(1, 1) > 0)) return corrupt_data(n + " focal lengths must be positive");
  if (K(2, 0) != 0 || K(2, 1) != 0 || K(2, 2) != 1)
    return corrupt_data(n + " matrix last row must be 0 0 1");
  if (!all_finite(dist)) return corrupt_data(n + " distortion has non-finite entries");
  if (!(dist.empty() || dist.size() == 4 || dist.size() == 5 || dist.size() == 8 ||
        dist.size() == 12 || dist.size() == 14))
    return corrupt_data(n + " distortion must have 0, 4, 5, 8, 12 or 14 coefficients, has " +
                        std::to_string(dist.size()));
  if (width <= 0 || height <= 0)
    return corrupt_data(n + " image size must be positive, is " + size_text({width, height}));
  return Status::ok();
}

bool finite_plane(const cv::Mat& xyz, const cv::Mat& mask) {
  for (int y = 0; y < xyz.rows; ++y) {
    const auto* p = xyz.ptr<cv::Vec3f>(y);
    const uint8_t* m = mask.ptr<uint8_t>(y);
    for (int x = 0; x < xyz.cols; ++x)
      if (m[x] && !(std::isfinite(p[x][0]) && std::isfinite(p[x][1]) && std::isfinite(p[x][2])))
        return false;
  }
  return true;
}

}  // namespace

Status Calibration::check() const {
  GVKIT_RETURN_IF_ERROR(
      check_intrinsics("camera", camera_K, camera_dist, camera_width, camera_height));
  GVKIT_RETURN_IF_ERROR(check_intrinsics("projector", projector_K, projector_dist, projector_width,
                                         projector_height));
  if (!all_finite(R_cam_from_proj) || !all_finite(cv::Matx31d(t_cam_from_proj_mm)))
    return corrupt_data("camera-from-projector transform has non-finite entries");
  const cv::Matx33d should_be_eye = R_cam_from_proj * R_cam_from_proj.t();
  if (cv::norm(should_be_eye - cv::Matx33d::eye(), cv::NORM_INF) > 1e-3 ||
      std::abs(cv::determinant(R_cam_from_proj) - 1.0) > 1e-3)
    return corrupt_data("camera-from-projector rotation is not a rotation matrix");
  if (!(baseline_mm() > 1e-6))
    return failed_precondition("camera and projector centres coincide (zero baseline)");
  if (!std::isfinite(fringe_pitch_px) || fringe_pitch_px < 0)
    return corrupt_data("fringe pitch must be finite and non-negative");
  return Status::ok();
}

Status FringeSet::check() const {
  if (images.empty()) return invalid_argument("fringe set has no images");
  const cv::Size size0 = images.front().size();
  for (size_t i = 0; i < images.size(); ++i) {
    const cv::Mat& im = images[i];
    if (im.empty()) return invalid_argument("image " + std::to_string(i) + " is empty");
    if (im.channels() != 1 || (im.depth() != CV_8U && im.depth() != CV_16U))
      return unsupported("image " + std::to_string(i) + " must be 8- or 16-bit grey");
    if (im.size() != size0)
      return invalid_argument("image " + std::to_string(i) + ": size " + size_text(im.size()) +
                              ", expected " + size_text(size0));
  }
  if (!texture.empty() && texture.size() != size0)
    return invalid_argument("texture: size " + size_text(texture.size()) + ", expected " +
                            size_text(size0));
  return Status::ok();
}

double RangeScan::valid_fraction() const {
  if (valid.empty()) return 0.0;
  return static_cast<double>(cv::countNonZero(valid)) / static_cast<double>(valid.total());
}

Status RangeScan::check() const {
  if (xyz_mm.empty() || xyz_mm.type() != CV_32FC3) return corrupt_data("xyz must be CV_32FC3");
  const cv::Size s = xyz_mm.size();
  if (valid.type() != CV_8U || valid.size() != s)
    return corrupt_data("valid mask must be CV_8U " + size_text(s));
  if (!texture.empty() && (texture.type() != CV_32F || texture.size() != s))
    return corrupt_data("texture must be CV_32F " + size_text(s));
  if (!quality.empty() && (quality.type() != CV_32F || quality.size() != s))
    return corrupt_data("quality must be CV_32F " + size_text(s));
  if (!finite_plane(xyz_mm, valid)) return corrupt_data("a valid pixel has non-finite xyz");
  return Status::ok();
}

Status GeometryImage::check() const {
  if (xyz_mm.empty() || xyz_mm.type() != CV_32FC3) return corrupt_data("xyz must be CV_32FC3");
  const cv::Size s = xyz_mm.size();
  if (domain_mask.type() != CV_8U || domain_mask.size() != s)
    return corrupt_data("domain mask must be CV_8U " + size_text(s));
  if (!texture.empty() && (texture.type() != CV_32F || texture.size() != s))
    return corrupt_data("texture must be CV_32F " + size_text(s));
  if (!finite_plane(xyz_mm, domain_mask)) return corrupt_data("a domain pixel has non-finite xyz");
  return Status::ok();
}

}  // namespace gvkit
