#include "gvkit/capture/reconstructor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "gvkit/core/log.hpp"

namespace gvkit::capture {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

std::string size_text(cv::Size s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

}  // namespace

Status ReconstructOptions::check() const {
  if (!(depth_prior_mm > 0 && std::isfinite(depth_prior_mm)))
    return invalid_argument("depth prior must be a positive distance in mm");
  if (!(min_depth_mm >= 0 && max_depth_mm > min_depth_mm && std::isfinite(max_depth_mm)))
    return invalid_argument("depth range must satisfy 0 <= min < max (mm)");
  return Status::ok();
}

// The column plane of projector column u (undistorted), in projector coordinates, has normal
// n(u) = (fx, skew, cx - u) through the projector's centre. A camera ray X = s * d meets it
// where n . (R d s + t) = 0, with R, t = proj_from_cam:
//   s = (t2 * u - (fx t0 + skew t1 + cx t2)) / (alpha - u * beta),
//   alpha = fx (Rd)0 + skew (Rd)1 + cx (Rd)2,  beta = (Rd)2.
// alpha and beta are per-pixel tables; d = (x, y, 1) so s is the depth z.
Result<Reconstructor> Reconstructor::create(const Calibration& calibration,
                                            const ReconstructOptions& options) {
  Status s = calibration.check();
  if (!s) return s.with_context("calibration");
  GVKIT_RETURN_IF_ERROR(options.check());
  Reconstructor r;
  r.calibration_ = calibration;
  r.options_ = options;
  if (!r.projector_lens_.set(calibration.projector_dist))
    return unsupported("calibration: projector distortion with " +
                       std::to_string(calibration.projector_dist.size()) +
                       " coefficients is not supported (use 4, 5 or 8)");
  const cv::Matx33d& Kp = calibration.projector_K;
  const cv::Matx33d R = calibration.R_proj_from_cam();
  const cv::Vec3d t = calibration.t_proj_from_cam_mm();
  const double fx = Kp(0, 0), skew = Kp(0, 1), cx = Kp(0, 2);

  // Parallel geometry: the camera centre (t in projector coordinates) lies in every column
  // plane, so no ray meets a plane at a single point.
  double max_distance = 0;
  for (double u : {0.0, 0.5 * calibration.projector_width, 1.0 * calibration.projector_width}) {
    const cv::Vec3d n(fx, skew, cx - u);
    max_distance = std::max(max_distance, std::abs(n.dot(t)) / cv::norm(n));
  }
  if (max_distance < 1e-3 * calibration.baseline_mm())
    return failed_precondition(
        "calibration: the baseline lies in the projector's column planes (camera rays and fringe "
        "planes are parallel): cannot triangulate; the fringes must vary across the baseline");

  r.numerator_a_ = -(fx * t[0] + skew * t[1] + cx * t[2]);
  r.numerator_b_ = t[2];
  const int w = calibration.camera_width, h = calibration.camera_height;
  std::vector<cv::Point2f> pixels;
  pixels.reserve(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) pixels.emplace_back(static_cast<float>(x), static_cast<float>(y));
  std::vector<cv::Point2f> normalized;
  if (calibration.camera_dist.empty()) {
    const cv::Matx33d& K = calibration.camera_K;
    normalized.resize(pixels.size());
    for (size_t i = 0; i < pixels.size(); ++i) {
      const double yn = (pixels[i].y - K(1, 2)) / K(1, 1);
      normalized[i] =
          cv::Point2f(static_cast<float>((pixels[i].x - K(0, 2) - K(0, 1) * yn) / K(0, 0)),
                      static_cast<float>(yn));
    }
  } else {
    cv::undistortPoints(
        pixels, normalized, calibration.camera_K, calibration.camera_dist, cv::noArray(),
        cv::noArray(),
        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 40, 1e-12));
  }
  r.ray_.create(h, w, CV_32FC3);
  r.alpha_.create(h, w, CV_32F);
  r.beta_.create(h, w, CV_32F);
  if (!r.projector_lens_.none) r.rotated_ray_.create(h, w, CV_64FC3);
  for (int i = 0; i < w * h; ++i) {
    const cv::Vec3d d(normalized[i].x, normalized[i].y, 1.0);
    const cv::Vec3d rd = R * d;
    r.ray_.ptr<cv::Vec3f>()[i] = cv::Vec3f(d);
    r.alpha_.ptr<float>()[i] = static_cast<float>(fx * rd[0] + skew * rd[1] + cx * rd[2]);
    r.beta_.ptr<float>()[i] = static_cast<float>(rd[2]);
    if (!r.projector_lens_.none) r.rotated_ray_.ptr<cv::Vec3d>()[i] = rd;
  }
  return r;
}

float Reconstructor::depth_at(int i, float u) const {
  const float denominator = alpha_.ptr<float>()[i] - u * beta_.ptr<float>()[i];
  float z = static_cast<float>(numerator_b_ * u + numerator_a_) / denominator;
  if (!projector_lens_.none && std::isfinite(z)) {
    // The distorted column is a curved surface: find the depth along the ray at which the
    // projector's distorted column equals u (secant iterations from the plane solution).
    const cv::Vec3d rd = rotated_ray_.ptr<cv::Vec3d>()[i];
    const cv::Vec3d t = calibration_.t_proj_from_cam_mm();
    const cv::Matx33d& K = calibration_.projector_K;
    auto column_error = [&](double s) {
      const cv::Vec3d p = rd * s + t;
      double xd, yd;
      projector_lens_.apply(p[0] / p[2], p[1] / p[2], xd, yd);
      return K(0, 0) * xd + K(0, 1) * yd + K(0, 2) - u;
    };
    double s0 = z, s1 = z * 1.001;
    double e0 = column_error(s0), e1 = column_error(s1);
    for (int it = 0; it < 8 && std::abs(s1 - s0) > 1e-5 && e1 != e0; ++it) {
      const double s2 = s1 - e1 * (s1 - s0) / (e1 - e0);
      s0 = s1;
      e0 = e1;
      s1 = s2;
      e1 = column_error(s1);
    }
    z = static_cast<float>(s1);
  }
  if (!(z >= options_.min_depth_mm && z <= options_.max_depth_mm)) return kNaN;
  return z;
}

cv::Mat Reconstructor::triangulate_columns(const cv::Mat& projector_u) const {
  GVKIT_CHECK(projector_u.type() == CV_32F && projector_u.size() == camera_size(),
              "projector_u must be CV_32F of the camera size");
  cv::Mat xyz(projector_u.size(), CV_32FC3);
  const float zmin = static_cast<float>(options_.min_depth_mm);
  const float zmax = static_cast<float>(options_.max_depth_mm);
  const float na = static_cast<float>(numerator_a_), nb = static_cast<float>(numerator_b_);
  for (int y = 0; y < xyz.rows; ++y) {
    const float* u = projector_u.ptr<float>(y);
    const float* alpha = alpha_.ptr<float>(y);
    const float* beta = beta_.ptr<float>(y);
    const cv::Vec3f* ray = ray_.ptr<cv::Vec3f>(y);
    cv::Vec3f* out = xyz.ptr<cv::Vec3f>(y);
    if (projector_lens_.none) {
      for (int x = 0; x < xyz.cols; ++x) {
        const float z = (nb * u[x] + na) / (alpha[x] - u[x] * beta[x]);
        const bool ok = z >= zmin && z <= zmax;  // false for NaN
        const float s = ok ? z : kNaN;
        out[x] = cv::Vec3f(ray[x][0] * s, ray[x][1] * s, s);
      }
    } else {
      for (int x = 0; x < xyz.cols; ++x) {
        const float z = std::isfinite(u[x]) ? depth_at(y * xyz.cols + x, u[x]) : kNaN;
        out[x] = cv::Vec3f(ray[x][0] * z, ray[x][1] * z, z);
      }
    }
  }
  return xyz;
}

cv::Mat Reconstructor::triangulate_columns_reference(const cv::Mat& projector_u) const {
  GVKIT_CHECK(projector_u.type() == CV_32F && projector_u.size() == camera_size(),
              "projector_u must be CV_32F of the camera size");
  const Calibration& c = calibration_;
  const cv::Matx33d R = c.R_proj_from_cam(), R_cp = c.R_cam_from_proj;
  const cv::Vec3d t = c.t_proj_from_cam_mm();
  cv::Vec3d rvec;
  cv::Rodrigues(R, rvec);
  const cv::Vec3d centre = c.t_cam_from_proj_mm;  // projector centre in camera coordinates
  const cv::Matx33d Kp_inv = c.projector_K.inv();
  cv::Mat xyz(projector_u.size(), CV_32FC3, cv::Scalar::all(kNaN));
  for (int y = 0; y < xyz.rows; ++y)
    for (int x = 0; x < xyz.cols; ++x) {
      const double u = projector_u.at<float>(y, x);
      if (!std::isfinite(u)) continue;
      std::vector<cv::Point2d> px{{static_cast<double>(x), static_cast<double>(y)}}, n;
      cv::undistortPoints(
          px, n, c.camera_K, c.camera_dist, cv::noArray(), cv::noArray(),
          cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 40, 1e-12));
      const cv::Vec3d d(n[0].x, n[0].y, 1.0);
      // Plane through the projector centre and the rays of (u, 0) and (u, height).
      const cv::Vec3d a = R_cp * (Kp_inv * cv::Vec3d(u, 0, 1));
      const cv::Vec3d b = R_cp * (Kp_inv * cv::Vec3d(u, c.projector_height, 1));
      const cv::Vec3d normal = a.cross(b);
      double s = normal.dot(centre) / normal.dot(d);
      if (!c.projector_dist.empty()) {
        auto column_error = [&](double depth) {
          std::vector<cv::Point3d> p{cv::Point3d(d * depth)};
          std::vector<cv::Point2d> q;
          cv::projectPoints(p, rvec, cv::Vec3d(t), c.projector_K, c.projector_dist, q);
          return q[0].x - u;
        };
        for (int it = 0; it < 20; ++it) {
          const double h = 1e-3, e = column_error(s);
          const double slope = (column_error(s + h) - column_error(s - h)) / (2 * h);
          if (slope == 0) break;
          const double step = e / slope;
          s -= step;
          if (std::abs(step) < 1e-7) break;
        }
      }
      if (!(s >= options_.min_depth_mm && s <= options_.max_depth_mm)) continue;
      xyz.at<cv::Vec3f>(y, x) = cv::Vec3f(d * s);
    }
  return xyz;
}

// Regions are resolved largest first. The largest takes the period offset that puts its median
// depth nearest the prior. Each further region that lies near resolved pixels (across a shadow
// or a gap of low modulation) takes the offset that continues their depth best; isolated regions
// fall back to the prior.
void Reconstructor::resolve_regions(PhaseMap& phase) const {
  if (phase.absolute || phase.region_count == 0) return;
  const int w = phase.phase.cols, h = phase.phase.rows;
  const int n = w * h;
  const int* region = phase.region.ptr<int>();
  float* ph = phase.phase.ptr<float>();
  std::vector<std::vector<int>> members(phase.region_count + 1);
  for (int i = 0; i < n; ++i)
    if (region[i] > 0) members[region[i]].push_back(i);
  std::vector<int> order;
  for (int r = 1; r <= phase.region_count; ++r) order.push_back(r);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return members[a].size() > members[b].size(); });

  const float two_pi = static_cast<float>(2 * CV_PI);
  const float pitch = static_cast<float>(phase.pitch_px);
  const int periods = static_cast<int>(std::ceil(calibration_.projector_width / phase.pitch_px));
  const float u_lo = -0.5f * pitch, u_hi = calibration_.projector_width + 0.5f * pitch;
  std::vector<char> resolved(n, 0);
  std::vector<float> resolved_depth(n, kNaN);
  auto candidate_depth = [&](int i, int k) {
    const float u = (ph[i] / two_pi + static_cast<float>(k)) * pitch;
    return (u < u_lo || u > u_hi) ? kNaN : depth_at(i, u);
  };
  constexpr int kSamples = 63, kReach = 24;
  for (int r : order) {
    const auto& m = members[r];
    const size_t stride = std::max<size_t>(1, m.size() / kSamples);
    // Pairs (sample pixel, depth of the nearest resolved pixel along its row or column).
    std::vector<std::pair<int, float>> pairs;
    for (size_t j = 0; j < m.size(); j += std::max<size_t>(1, stride / 4)) {
      const int i = m[j], x = i % w, y = i / w;
      float best_depth = kNaN;
      int best_distance = kReach + 1;
      const int dirs[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
      for (const auto& d : dirs)
        for (int step = 1; step < best_distance; ++step) {
          const int xx = x + d[0] * step, yy = y + d[1] * step;
          if (xx < 0 || yy < 0 || xx >= w || yy >= h) break;
          const int q = yy * w + xx;
          if (region[q] == r) break;  // still inside this region: not a boundary direction
          if (resolved[q] && std::isfinite(resolved_depth[q])) {
            best_depth = resolved_depth[q];
            best_distance = step;
            break;
          }
        }
      if (std::isfinite(best_depth)) pairs.emplace_back(i, best_depth);
    }
    double best_error = INFINITY;
    int best_k = 0;
    bool found = false;
    const bool by_neighbours = pairs.size() >= 5;
    for (int k = -periods - 1; k <= periods + 1; ++k) {
      std::vector<float> errors;
      int tried = 0;
      if (by_neighbours) {
        for (const auto& [i, z_near] : pairs) {
          ++tried;
          const float z = candidate_depth(i, k);
          if (std::isfinite(z)) errors.push_back(std::abs(z - z_near));
        }
      } else {
        for (size_t j = 0; j < m.size(); j += stride) {
          ++tried;
          const float z = candidate_depth(m[j], k);
          if (std::isfinite(z)) errors.push_back(z);
        }
      }
      if (errors.empty() || static_cast<int>(errors.size()) * 2 < tried) continue;
      std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
      const double median = errors[errors.size() / 2];
      const double error = by_neighbours ? median : std::abs(median - options_.depth_prior_mm);
      if (error < best_error) {
        best_error = error;
        best_k = k;
        found = true;
      }
    }
    const float offset = found ? two_pi * static_cast<float>(best_k) : kNaN;
    for (int i : m) {
      ph[i] += offset;
      resolved[i] = 1;
    }
    if (found && r != order.back())
      for (int i : m) resolved_depth[i] = depth_at(i, ph[i] / two_pi * pitch);
  }
}

RangeScan Reconstructor::triangulate(const PhaseMap& decoded) const {
  PhaseMap phase = decoded;
  if (!phase.absolute) {
    phase.phase = decoded.phase.clone();
    resolve_regions(phase);
  }
  const cv::Mat u = projector_column(phase);
  RangeScan scan;
  scan.xyz_mm = options_.reference ? triangulate_columns_reference(u) : triangulate_columns(u);
  scan.valid.create(u.size(), CV_8U);
  for (int y = 0; y < u.rows; ++y) {
    cv::Vec3f* p = scan.xyz_mm.ptr<cv::Vec3f>(y);
    const uint8_t* ok = phase.valid.ptr<uint8_t>(y);
    uint8_t* v = scan.valid.ptr<uint8_t>(y);
    for (int x = 0; x < u.cols; ++x) {
      v[x] = (ok[x] && std::isfinite(p[x][2])) ? 255 : 0;
      if (!v[x]) p[x] = cv::Vec3f(kNaN, kNaN, kNaN);
    }
  }
  scan.texture = phase.texture;
  scan.quality = phase.quality;
  return scan;
}

Result<RangeScan> Reconstructor::reconstruct(const FringeSet& fringes,
                                             const PatternSet& patterns) const {
  const std::string frame = "frame " + std::to_string(fringes.index);
  if (!fringes.images.empty() && !fringes.images[0].empty() &&
      fringes.images[0].size() != camera_size())
    return invalid_argument(frame + ": image size " + size_text(fringes.images[0].size()) +
                            " differs from the calibration's camera size " +
                            size_text(camera_size()));
  GVKIT_ASSIGN_OR_RETURN(PhaseMap phase, patterns.decode(fringes, calibration_.projector_width));
  RangeScan scan = triangulate(phase);
  if (!fringes.texture.empty()) {
    const double range = fringes.texture.depth() == CV_16U  ? 65535.0
                         : fringes.texture.depth() == CV_8U ? 255.0
                                                            : 1.0;
    fringes.texture.convertTo(scan.texture, CV_32F, 1.0 / range);
  }
  scan.index = fringes.index;
  scan.timestamp = fringes.timestamp;
  if (cv::countNonZero(scan.valid) == 0)
    logger().warn("{}: no valid pixel (dark, saturated or no fringes): empty scan", frame);
  return scan;
}

Result<RangeScan> reconstruct(const FringeSet& fringes, const PatternSet& patterns,
                              const Calibration& calibration, const ReconstructOptions& options) {
  GVKIT_ASSIGN_OR_RETURN(Reconstructor r, Reconstructor::create(calibration, options));
  return r.reconstruct(fringes, patterns);
}

}  // namespace gvkit::capture
