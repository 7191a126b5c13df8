#include "gvkit/capture/stereo_reconstructor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "gvkit/core/log.hpp"

namespace gvkit::capture {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

std::string size_text(cv::Size s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

bool finite(const cv::Matx33d& m) {
  for (double v : m.val)
    if (!std::isfinite(v)) return false;
  return true;
}

// Projector column per pixel, NaN where the map is invalid.
cv::Mat columns(const PhaseMap& map) {
  cv::Mat u = projector_column(map);
  for (int y = 0; y < u.rows; ++y)
    for (int x = 0; x < u.cols; ++x)
      if (!map.valid.at<uint8_t>(y, x)) u.at<float>(y, x) = kNaN;
  return u;
}

// Bilinear resampling of a CV_32F map at (map_x, map_y); NaN when any of the four neighbours is
// NaN or outside (exact weights, unlike cv::remap's 1/32 px table).
cv::Mat resample(const cv::Mat& src, const cv::Mat& map_x, const cv::Mat& map_y) {
  cv::Mat out(map_x.size(), CV_32F);
  for (int y = 0; y < out.rows; ++y)
    for (int x = 0; x < out.cols; ++x) {
      const float sx = map_x.at<float>(y, x), sy = map_y.at<float>(y, x);
      const int x0 = static_cast<int>(std::floor(sx)), y0 = static_cast<int>(std::floor(sy));
      if (!(x0 >= 0 && y0 >= 0 && x0 + 1 < src.cols && y0 + 1 < src.rows)) {
        out.at<float>(y, x) = kNaN;
        continue;
      }
      const float fx = sx - x0, fy = sy - y0;
      const float a = src.at<float>(y0, x0), b = src.at<float>(y0, x0 + 1);
      const float c = src.at<float>(y0 + 1, x0), d = src.at<float>(y0 + 1, x0 + 1);
      out.at<float>(y, x) =
          (1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * c + fx * d);  // NaN propagates
    }
  return out;
}

// Sub-pixel position along a row where u crosses `target`, searching outwards from `hint`; NaN
// when no segment of finite, continuous values (steps at most max_step) brackets it.
float find_crossing(const float* u, int width, float target, int hint, float max_step) {
  hint = std::clamp(hint, 0, width - 2);
  for (int r = 0; r < width; ++r) {
    for (int k : {hint + r, hint - r}) {
      if (k < 0 || k + 1 >= width || (r == 0 && k != hint)) continue;
      const float a = u[k], b = u[k + 1];
      if (!(std::isfinite(a) && std::isfinite(b)) || std::abs(b - a) > max_step || a == b) continue;
      if ((a - target) * (b - target) <= 0) return k + (target - a) / (b - a);
    }
    if (hint - r < 0 && hint + r + 1 >= width) break;
  }
  return kNaN;
}

// Median |step| of u between horizontal neighbours (a scale for what is continuous).
float median_step(const cv::Mat& u) {
  std::vector<float> steps;
  for (int y = 0; y < u.rows; y += 4)
    for (int x = 0; x + 1 < u.cols; x += 2) {
      const float d = u.at<float>(y, x + 1) - u.at<float>(y, x);
      if (std::isfinite(d)) steps.push_back(std::abs(d));
    }
  if (steps.empty()) return 1;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return std::max(steps[steps.size() / 2], 1e-3f);
}

}  // namespace

Status StereoCalibration::check() const {
  if (size.width <= 0 || size.height <= 0) return invalid_argument("stereo: no image size");
  for (const cv::Matx33d* K : {&left_K, &right_K})
    if (!finite(*K) || (*K)(0, 0) <= 0 || (*K)(1, 1) <= 0)
      return corrupt_data("stereo: camera matrices must be finite with positive focal lengths");
  const cv::Matx33d should_be_eye = R_right_from_left * R_right_from_left.t();
  if (!finite(R_right_from_left) || cv::norm(should_be_eye - cv::Matx33d::eye()) > 1e-3 ||
      std::abs(cv::determinant(R_right_from_left) - 1) > 1e-3)
    return corrupt_data("stereo: R is not a rotation matrix");
  if (!(cv::norm(t_right_from_left_mm) > 1e-6))
    return failed_precondition("stereo: the two cameras' centres coincide (zero baseline)");
  return Status::ok();
}

Result<StereoCalibration> stereo_calibration(const TwoDeviceCalibration& d, cv::Size image_size) {
  for (cv::Size recorded : {d.size1, d.size2})
    if (recorded.area() > 0 && recorded != image_size)
      return failed_precondition("the stereo calibration is for " + size_text(recorded) +
                                 " images, the images are " + size_text(image_size));
  StereoCalibration c;
  c.left_K = d.K1;
  c.right_K = d.K2;
  c.left_dist = d.dist1;
  c.right_dist = d.dist2;
  c.size = image_size;
  c.R_right_from_left = d.R_2_from_1;
  c.t_right_from_left_mm = d.t_2_from_1_mm;
  if (!d.R1.empty() && !d.R2.empty() && !d.P1.empty() && !d.P2.empty() && !d.Q.empty()) {
    c.R1 = d.R1;
    c.R2 = d.R2;
    c.P1 = d.P1;
    c.P2 = d.P2;
    c.Q = d.Q;
  }
  GVKIT_RETURN_IF_ERROR(c.check());
  return c;
}

Status StereoOptions::check() const {
  if (!(min_depth_mm > 0 && max_depth_mm > min_depth_mm))
    return invalid_argument("stereo depth range must satisfy 0 < min < max");
  if (projector_width < 8) return invalid_argument("projector width must be >= 8 px");
  return Status::ok();
}

Result<StereoReconstructor> StereoReconstructor::create(const StereoCalibration& calibration,
                                                        const StereoOptions& options) {
  GVKIT_RETURN_IF_ERROR(calibration.check());
  GVKIT_RETURN_IF_ERROR(options.check());
  StereoReconstructor r;
  r.calibration_ = calibration;
  r.options_ = options;
  const cv::Mat K1(calibration.left_K), K2(calibration.right_K);
  const cv::Mat D1(calibration.left_dist, true), D2(calibration.right_dist, true);
  cv::Mat R1 = calibration.R1, R2 = calibration.R2, P1 = calibration.P1, P2 = calibration.P2,
          Q = calibration.Q;
  try {
    if (R1.empty())
      cv::stereoRectify(K1, D1, K2, D2, calibration.size, cv::Mat(calibration.R_right_from_left),
                        cv::Mat(calibration.t_right_from_left_mm), R1, R2, P1, P2, Q,
                        cv::CALIB_ZERO_DISPARITY, -1, calibration.size);
    cv::initUndistortRectifyMap(K2, D2, R2, P2, calibration.size, CV_32FC1, r.right_map_x_,
                                r.right_map_y_);
    std::vector<cv::Point2f> pixels, rectified;
    for (int y = 0; y < calibration.size.height; ++y)
      for (int x = 0; x < calibration.size.width; ++x) pixels.emplace_back(x, y);
    cv::undistortPoints(pixels, rectified, K1, D1, R1, P1);
    r.left_rectified_ = cv::Mat(rectified, true).reshape(2, calibration.size.height);
  } catch (const cv::Exception& e) {
    return failed_precondition(std::string("stereo: cannot rectify the pair: ") + e.what());
  }
  R1.convertTo(R1, CV_64F);
  Q.convertTo(Q, CV_64F);
  for (int i = 0; i < 9; ++i) r.R1_.val[i] = R1.at<double>(i / 3, i % 3);
  for (int i = 0; i < 16; ++i) r.Q_.val[i] = Q.at<double>(i / 4, i % 4);
  return r;
}

Result<RangeScan> StereoReconstructor::reconstruct(const FringeSet& left, const FringeSet& right,
                                                   const PatternSet& patterns) const {
  const std::string frame = "frame " + std::to_string(left.index);
  for (const auto& [name, set] : {std::pair{"left", &left}, std::pair{"right", &right}})
    if (set->size() != calibration_.size)
      return invalid_argument(frame + ": " + name + " camera images are " + size_text(set->size()) +
                              ", the stereo calibration's " + size_text(calibration_.size));
  if (!patterns.absolute())
    return invalid_argument("pattern set " + patterns.name() +
                            " is unwrapped spatially: its phase differs between the cameras by "
                            "unknown whole periods; a camera pair needs an absolute pattern set "
                            "(mf, het, gray, cgray)");
  Result<PhaseMap> l = patterns.decode(left, options_.projector_width);
  if (!l) return l.status().with_context("left camera");
  Result<PhaseMap> r = patterns.decode(right, options_.projector_width);
  if (!r) return r.status().with_context("right camera");
  RangeScan scan = match(*l, *r);
  scan.index = left.index;
  scan.timestamp = left.timestamp;
  if (cv::countNonZero(scan.valid) == 0)
    logger().warn("{}: no pixel matched between the cameras: empty scan", frame);
  return scan;
}

RangeScan StereoReconstructor::match(const PhaseMap& left, const PhaseMap& right) const {
  const cv::Size size = calibration_.size;
  const cv::Mat u_left = columns(left);
  const cv::Mat u_right = resample(columns(right), right_map_x_, right_map_y_);
  const float max_step = 4 * median_step(u_right);
  RangeScan scan;
  scan.xyz_mm = cv::Mat(size, CV_32FC3, cv::Scalar::all(kNaN));
  scan.valid = cv::Mat(size, CV_8U, cv::Scalar(0));
  scan.texture = left.texture.clone();
  scan.quality = left.quality.clone();
  const cv::Matx33d rect_to_left = R1_.t();
  for (int y = 0; y < size.height; ++y) {
    float disparity_hint = kNaN;  // the last match of this row
    for (int x = 0; x < size.width; ++x) {
      const float u = u_left.at<float>(y, x);
      if (!std::isfinite(u)) continue;
      const cv::Vec2f p = left_rectified_.at<cv::Vec2f>(y, x);
      const int row = static_cast<int>(std::floor(p[1]));
      if (row < 0 || row + 1 >= size.height) continue;
      const int hint = static_cast<int>(
          std::lround(std::isfinite(disparity_hint) ? p[0] - disparity_hint : p[0]));
      // The crossing in the two rectified rows around p; interpolated to p's row.
      const float a = find_crossing(u_right.ptr<float>(row), size.width, u, hint, max_step);
      const float b = find_crossing(u_right.ptr<float>(row + 1), size.width, u,
                                    std::isfinite(a) ? static_cast<int>(a) : hint, max_step);
      const float f = p[1] - row;
      float x_right;
      if (std::isfinite(a) && std::isfinite(b) && std::abs(a - b) < 2)
        x_right = (1 - f) * a + f * b;
      else if (std::isfinite(a) && f < 0.25f)
        x_right = a;
      else if (std::isfinite(b) && f > 0.75f)
        x_right = b;
      else
        continue;
      const float disparity = p[0] - x_right;
      const cv::Vec4d h = Q_ * cv::Vec4d(p[0], p[1], disparity, 1);
      if (!(std::abs(h[3]) > 1e-12)) continue;
      const cv::Vec3d rect(h[0] / h[3], h[1] / h[3], h[2] / h[3]);
      const cv::Vec3d point = rect_to_left * rect;
      if (!(point[2] >= options_.min_depth_mm && point[2] <= options_.max_depth_mm)) continue;
      scan.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(point);
      scan.valid.at<uint8_t>(y, x) = 255;
      disparity_hint = disparity;
    }
  }
  return scan;
}

}  // namespace gvkit::capture
