#include "gvkit/capture/projector_calibration.hpp"

#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace gvkit::capture {
namespace {

// Projector coordinate at a corner: a plane fitted to the decoded map in a window around it.
bool fit_at(const cv::Mat& map, const cv::Mat& valid, cv::Point2f corner, int half, double& out) {
  const int cx = static_cast<int>(std::lround(corner.x)),
            cy = static_cast<int>(std::lround(corner.y));
  cv::Mat A(0, 3, CV_64F), b(0, 1, CV_64F);
  for (int y = cy - half; y <= cy + half; ++y)
    for (int x = cx - half; x <= cx + half; ++x) {
      if (x < 0 || y < 0 || x >= map.cols || y >= map.rows || !valid.at<uint8_t>(y, x)) continue;
      const double row[3] = {1.0, x - corner.x, y - corner.y};
      A.push_back(cv::Mat(1, 3, CV_64F, const_cast<double*>(row)).clone());
      b.push_back(static_cast<double>(map.at<float>(y, x)));
    }
  if (A.rows < (2 * half + 1) * (2 * half + 1) / 2) return false;
  cv::Mat coef;
  if (!cv::solve(A, b, coef, cv::DECOMP_SVD)) return false;
  out = coef.at<double>(0);
  return std::isfinite(out);
}

}  // namespace

Status CalibrationBoard::check() const {
  if (inner_corners_x < 3 || inner_corners_y < 3)
    return invalid_argument("board needs at least 3x3 inner corners");
  if (!(square_mm > 0)) return invalid_argument("board square size must be > 0 mm");
  return Status::ok();
}

std::vector<cv::Point3f> CalibrationBoard::object_points() const {
  std::vector<cv::Point3f> p;
  for (int y = 0; y < inner_corners_y; ++y)
    for (int x = 0; x < inner_corners_x; ++x)
      p.emplace_back(static_cast<float>(x * square_mm), static_cast<float>(y * square_mm), 0.0f);
  return p;
}

Status ProjectorCalibrationOptions::check() const {
  if (projector_width < 8 || projector_height < 8)
    return invalid_argument("projector size must be at least 8x8");
  if (fit_window_px < 1 || fit_window_px > 50)
    return invalid_argument("fit window must be 1..50 px");
  return Status::ok();
}

Result<std::vector<cv::Mat>> calibration_patterns(const ProjectorCalibrationOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  GVKIT_ASSIGN_OR_RETURN(auto set, create_pattern_set(options.pattern));
  const cv::Size size(options.projector_width, options.projector_height);
  std::vector<cv::Mat> out{cv::Mat(size, CV_32F, cv::Scalar(1.0))};
  for (const cv::Mat& m : set->generate(size)) out.push_back(m);
  // Horizontal fringes: the vertical patterns of the transposed projector, transposed back.
  for (const cv::Mat& m : set->generate({size.height, size.width})) out.push_back(m.t());
  return out;
}

Result<ProjectorCalibrationResult> calibrate_projector_camera(
    const std::vector<FringeSet>& captures, const CalibrationBoard& board,
    const ProjectorCalibrationOptions& options) {
  GVKIT_RETURN_IF_ERROR(board.check());
  GVKIT_RETURN_IF_ERROR(options.check());
  GVKIT_ASSIGN_OR_RETURN(auto set, create_pattern_set(options.pattern));
  const int n = set->image_count();
  const cv::Size pattern_size(board.inner_corners_x, board.inner_corners_y);
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> camera_points, projector_points;
  ProjectorCalibrationResult result;
  cv::Size camera_size;
  for (size_t i = 0; i < captures.size(); ++i) {
    const FringeSet& c = captures[i];
    const std::string name = "capture " + std::to_string(i);
    if (static_cast<int>(c.images.size()) != 1 + 2 * n)
      return invalid_argument(name + ": " + std::to_string(c.images.size()) + " images, expected " +
                              std::to_string(1 + 2 * n) + " (white + 2 x " + set->name() + ")");
    Status s = c.check();
    if (!s) return s.with_context(name);
    if (camera_size.area() == 0) camera_size = c.size();
    if (c.size() != camera_size) return invalid_argument(name + ": image size differs");
    cv::Mat white8;
    c.images[0].convertTo(white8, CV_8U, c.images[0].depth() == CV_16U ? 1.0 / 257 : 1.0);
    std::vector<cv::Point2f> corners;
    if (!cv::findChessboardCorners(white8, pattern_size, corners,
                                   cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
      result.skipped.push_back(name + ": board not found");
      continue;
    }
    cv::cornerSubPix(white8, corners, cv::Size(5, 5), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 50, 1e-4));
    FringeSet vertical, horizontal;
    vertical.index = horizontal.index = static_cast<int64_t>(i);
    vertical.images.assign(c.images.begin() + 1, c.images.begin() + 1 + n);
    horizontal.images.assign(c.images.begin() + 1 + n, c.images.end());
    GVKIT_ASSIGN_OR_RETURN(PhaseMap u_map, set->decode(vertical, options.projector_width));
    GVKIT_ASSIGN_OR_RETURN(PhaseMap v_map, set->decode(horizontal, options.projector_height));
    const cv::Mat u = projector_column(u_map), v = projector_column(v_map);
    std::vector<cv::Point2f> projected;
    bool all = true;
    for (const cv::Point2f& p : corners) {
      double pu, pv;
      if (!fit_at(u, u_map.valid, p, options.fit_window_px, pu) ||
          !fit_at(v, v_map.valid, p, options.fit_window_px, pv)) {
        all = false;
        break;
      }
      projected.emplace_back(static_cast<float>(pu), static_cast<float>(pv));
    }
    if (!all) {
      result.skipped.push_back(name + ": fringes not decoded at every corner");
      continue;
    }
    object.push_back(board.object_points());
    camera_points.push_back(corners);
    projector_points.push_back(projected);
  }
  if (object.size() < 3)
    return failed_precondition("calibration: only " + std::to_string(object.size()) +
                               " captures show the whole board decoded (need 3)");
  Calibration& cal = result.calibration;
  cv::Mat Kc, dc, Kp, dp;
  std::vector<cv::Mat> rv, tv;
  const int flags = cv::CALIB_FIX_K3;
  cal.camera_error_px =
      cv::calibrateCamera(object, camera_points, camera_size, Kc, dc, rv, tv, flags);
  const cv::Size projector_size(options.projector_width, options.projector_height);
  cal.projector_error_px =
      cv::calibrateCamera(object, projector_points, projector_size, Kp, dp, rv, tv, flags);
  cv::Mat R, T, E, F;
  cal.stereo_error_px = cv::stereoCalibrate(object, camera_points, projector_points, Kc, dc, Kp, dp,
                                            camera_size, R, T, E, F, cv::CALIB_FIX_INTRINSIC);
  cal.camera_K = cv::Matx33d(Kc);
  cal.projector_K = cv::Matx33d(Kp);
  cal.camera_dist.assign(dc.begin<double>(), dc.end<double>());
  cal.projector_dist.assign(dp.begin<double>(), dp.end<double>());
  cal.camera_width = camera_size.width;
  cal.camera_height = camera_size.height;
  cal.projector_width = options.projector_width;
  cal.projector_height = options.projector_height;
  // stereoCalibrate maps camera-1 (camera) coordinates into camera-2 (projector) ones.
  const cv::Matx33d R_proj_from_cam(R);
  const cv::Vec3d t_proj_from_cam(T.at<double>(0), T.at<double>(1), T.at<double>(2));
  cal.R_cam_from_proj = R_proj_from_cam.t();
  cal.t_cam_from_proj_mm = -(R_proj_from_cam.t() * t_proj_from_cam);
  cal.fringe_pitch_px = set->pitch_px(options.projector_width);
  result.poses_used = static_cast<int>(object.size());
  return result;
}

}  // namespace gvkit::capture
