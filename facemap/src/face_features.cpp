#include "gvkit/facemap/face_features.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <opencv2/imgproc.hpp>

namespace gvkit::facemap {

std::vector<int> required_landmarks() {
  std::vector<int> out{FaceLandmarks::kNoseTip};
  for (int i = 36; i < 68; ++i) out.push_back(i);
  return out;
}

Status lift_landmarks(const RangeScan& scan, FaceLandmarks* landmarks, double max_distance_px,
                      const cv::Mat& usable, LandmarkLiftReport* report) {
  if (static_cast<int>(landmarks->points_px.size()) != FaceLandmarks::kCount)
    return invalid_argument("landmarks: expected 68 image points, got " +
                            std::to_string(landmarks->points_px.size()));
  const cv::Mat& valid = usable.empty() ? scan.valid : usable;
  GVKIT_CHECK(valid.size() == scan.valid.size() && valid.type() == CV_8U,
              "lift_landmarks: usable mask must be CV_8U of the scan's size");
  LandmarkLiftReport local;
  if (!report) report = &local;
  *report = {};
  const int rows = valid.rows, cols = valid.cols;
  // Nearest usable pixel of every pixel: distance transform of the unusable set with labels.
  cv::Mat invalid = valid == 0, distance, labels;
  cv::distanceTransform(invalid, distance, labels, cv::DIST_L2, cv::DIST_MASK_PRECISE,
                        cv::DIST_LABEL_PIXEL);
  std::vector<cv::Point> label_pixel(static_cast<size_t>(rows) * cols + 1);
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x)
      if (valid.at<uint8_t>(y, x)) label_pixel[labels.at<int>(y, x)] = {x, y};

  std::vector<char> required(FaceLandmarks::kCount, 0);
  for (int i : required_landmarks()) required[i] = 1;
  landmarks->points_mm.assign(FaceLandmarks::kCount, cv::Vec3f());
  for (int i = 0; i < FaceLandmarks::kCount; ++i) {
    const cv::Point2f p = landmarks->points_px[i];
    char where[96];
    std::snprintf(where, sizeof where, "landmark %d at (%.1f, %.1f) px", i, p.x, p.y);
    const bool inside = p.x >= 0 && p.y >= 0 && p.x <= cols - 1 && p.y <= rows - 1;
    if (!inside) {
      if (required[i]) return failed_precondition(std::string(where) + " is outside the image");
    }
    const int x0 = std::clamp(static_cast<int>(std::floor(p.x)), 0, cols - 1);
    const int y0 = std::clamp(static_cast<int>(std::floor(p.y)), 0, rows - 1);
    const int x1 = std::min(x0 + 1, cols - 1), y1 = std::min(y0 + 1, rows - 1);
    const bool all_valid = valid.at<uint8_t>(y0, x0) && valid.at<uint8_t>(y0, x1) &&
                           valid.at<uint8_t>(y1, x0) && valid.at<uint8_t>(y1, x1);
    if (inside && all_valid) {
      const float fx = p.x - x0, fy = p.y - y0;
      const cv::Vec3f v = (1 - fx) * (1 - fy) * scan.xyz_mm.at<cv::Vec3f>(y0, x0) +
                          fx * (1 - fy) * scan.xyz_mm.at<cv::Vec3f>(y0, x1) +
                          (1 - fx) * fy * scan.xyz_mm.at<cv::Vec3f>(y1, x0) +
                          fx * fy * scan.xyz_mm.at<cv::Vec3f>(y1, x1);
      landmarks->points_mm[i] = v;
      continue;
    }
    const int yr = std::clamp(static_cast<int>(std::lround(p.y)), 0, rows - 1);
    const int xr = std::clamp(static_cast<int>(std::lround(p.x)), 0, cols - 1);
    const cv::Point nearest = label_pixel[labels.at<int>(yr, xr)];
    const double d = std::hypot(nearest.x - p.x, nearest.y - p.y);
    if (!valid.at<uint8_t>(nearest) || (required[i] && d > max_distance_px))
      return failed_precondition(std::string(where) + " is outside the valid scan (nearest " +
                                 "usable pixel " + std::to_string(static_cast<int>(d)) +
                                 " px away, limit " +
                                 std::to_string(static_cast<int>(max_distance_px)) + " px)");
    landmarks->points_mm[i] = scan.xyz_mm.at<cv::Vec3f>(nearest);
    if (required[i] && !valid.at<uint8_t>(yr, xr)) {
      ++report->snapped;
      report->max_snap_px = std::max(report->max_snap_px, d);
    }
  }
  return Status::ok();
}

cv::Mat valid_without_feature_interiors(const RangeScan& scan, const FaceLandmarks& landmarks,
                                        double min_inside_px, int* removed) {
  cv::Mat valid = scan.valid.clone();
  int count = 0;
  if (static_cast<int>(landmarks.points_px.size()) == FaceLandmarks::kCount) {
    auto cut = [&](const int* begin, const int* end) {
      std::vector<cv::Point2f> contour;
      for (const int* i = begin; i != end; ++i) contour.push_back(landmarks.points_px[*i]);
      const cv::Rect box = cv::boundingRect(contour) & cv::Rect(0, 0, valid.cols, valid.rows);
      for (int y = box.y; y < box.y + box.height; ++y)
        for (int x = box.x; x < box.x + box.width; ++x) {
          uint8_t& v = valid.at<uint8_t>(y, x);
          if (!v) continue;
          const double inside = cv::pointPolygonTest(
              contour, cv::Point2f(static_cast<float>(x), static_cast<float>(y)), true);
          if (inside > min_inside_px) {
            v = 0;
            ++count;
          }
        }
    };
    cut(kInnerMouthContour.data(), kInnerMouthContour.data() + kInnerMouthContour.size());
    cut(kRightEyeContour.data(), kRightEyeContour.data() + kRightEyeContour.size());
    cut(kLeftEyeContour.data(), kLeftEyeContour.data() + kLeftEyeContour.size());
  }
  if (removed) *removed = count;
  return valid;
}

std::vector<FeatureHole> feature_interior_holes(const Mesh& mesh,
                                                const std::vector<cv::Point>& vertex_pixel,
                                                const FaceLandmarks& landmarks,
                                                double max_outside_px, double max_outside_fraction,
                                                int min_edges) {
  GVKIT_CHECK(vertex_pixel.size() == mesh.n_vertices(), "feature holes: one pixel per vertex");
  std::vector<FeatureHole> out;
  if (static_cast<int>(landmarks.points_px.size()) != FaceLandmarks::kCount) return out;
  std::vector<cv::Point2f> contours[3];
  for (int i : kRightEyeContour) contours[0].push_back(landmarks.points_px[i]);
  for (int i : kLeftEyeContour) contours[1].push_back(landmarks.points_px[i]);
  for (int i : kInnerMouthContour) contours[2].push_back(landmarks.points_px[i]);
  cv::Rect2f boxes[3];
  for (int k = 0; k < 3; ++k) {
    cv::Point2f lo = contours[k].front(), hi = lo;
    for (const auto& p : contours[k]) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    }
    boxes[k] = cv::Rect2f(lo, hi);
  }
  // An eye's or lip's rim is a curve through its landmarks that bulges out of their polygon
  // between them (for six points on an ellipse, by up to 0.13 of its half-width).
  double tolerance[3];
  for (int k = 0; k < 3; ++k)
    tolerance[k] =
        max_outside_px + max_outside_fraction * 0.5 * std::max(boxes[k].width, boxes[k].height);
  std::vector<char> visited(mesh.n_halfedges(), 0);
  std::vector<cv::Point2f> loop;
  for (auto h : mesh.halfedges()) {
    if (!mesh.is_boundary(h) || visited[h.idx()]) continue;
    loop.clear();
    auto l = h;
    do {
      visited[l.idx()] = 1;
      loop.push_back(vertex_pixel[mesh.to_vertex_handle(l).idx()]);
      l = mesh.next_halfedge_handle(l);
    } while (l != h);
    // Small gaps (a missing pixel, a dropped triangle) cost the fill next to nothing, but one
    // outside its contour's path would cost the mask a second run: they are filled.
    if (static_cast<int>(loop.size()) < min_edges) continue;
    for (int k = 0; k < 3; ++k) {
      // The bounding box, grown by the tolerance, rejects the rim and far loops cheaply.
      const cv::Rect2f& b = boxes[k];
      const float t = static_cast<float>(tolerance[k]);
      bool inside = true;
      for (const auto& p : loop)
        inside = inside && p.x >= b.x - t && p.y >= b.y - t && p.x <= b.x + b.width + t &&
                 p.y <= b.y + b.height + t;
      for (size_t i = 0; i < loop.size() && inside; ++i)
        inside = cv::pointPolygonTest(contours[k], loop[i], true) >= -tolerance[k];
      if (inside) {
        out.push_back({h, k});
        break;
      }
    }
  }
  return out;
}

cv::Vec3d landmark_centroid(const FaceLandmarks& landmarks, const int* begin, const int* end) {
  cv::Vec3d c(0, 0, 0);
  for (const int* i = begin; i != end; ++i) c += cv::Vec3d(landmarks.points_mm[*i]);
  return c / static_cast<double>(end - begin);
}

}  // namespace gvkit::facemap
