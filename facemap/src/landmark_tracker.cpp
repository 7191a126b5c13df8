#include "gvkit/facemap/landmark_tracker.hpp"

#include <string>

#include <opencv2/video/tracking.hpp>

namespace gvkit::facemap {

Status LandmarkTrackerOptions::check() const {
  if (window_px < 5 || window_px > 101)
    return invalid_argument("landmark tracker: window must be in [5, 101] px");
  if (pyramid_levels < 0 || pyramid_levels > 8)
    return invalid_argument("landmark tracker: pyramid levels must be in [0, 8]");
  if (!(max_forward_backward_px > 0) || !(max_lost_fraction >= 0 && max_lost_fraction <= 1))
    return invalid_argument("landmark tracker: thresholds out of range");
  return Status::ok();
}

namespace {

cv::Mat to_8u(const cv::Mat& image) {
  if (image.depth() == CV_8U) return image;
  cv::Mat out;
  image.convertTo(out, CV_8U, 255.0);
  return out;
}

}  // namespace

LandmarkTracker::LandmarkTracker(const cv::Mat& first_image, const FaceLandmarks& first,
                                 const LandmarkDetector* detector,
                                 const LandmarkTrackerOptions& options)
    : previous_(to_8u(first_image)),
      points_(first.points_px),
      detector_(detector),
      options_(options) {
  GVKIT_CHECK(options.check().is_ok(), options.check().message());
  GVKIT_CHECK(static_cast<int>(points_.size()) == FaceLandmarks::kCount, "68 landmarks");
}

Result<FaceLandmarks> LandmarkTracker::track(const cv::Mat& image) {
  const cv::Mat next = to_8u(image);
  std::vector<cv::Point2f> forward, backward;
  std::vector<uchar> status_f, status_b;
  std::vector<float> error;
  const cv::Size window(options_.window_px, options_.window_px);
  cv::calcOpticalFlowPyrLK(previous_, next, points_, forward, status_f, error, window,
                           options_.pyramid_levels);
  cv::calcOpticalFlowPyrLK(next, previous_, forward, backward, status_b, error, window,
                           options_.pyramid_levels);
  int lost = 0;
  for (size_t i = 0; i < points_.size(); ++i)
    if (!status_f[i] || !status_b[i] ||
        cv::norm(backward[i] - points_[i]) > options_.max_forward_backward_px)
      ++lost;
  FaceLandmarks out;
  if (lost > options_.max_lost_fraction * FaceLandmarks::kCount) {
    if (!detector_)
      return failed_precondition("landmark tracking lost " + std::to_string(lost) +
                                 " of 68 points and no detector to recover");
    auto detected = detector_->detect(next);
    if (!detected.is_ok())
      return failed_precondition("landmark tracking lost " + std::to_string(lost) +
                                 " of 68 points; re-detection: " + detected.status().message());
    ++redetections_;
    out = std::move(detected).value();
  } else {
    out.points_px = forward;
  }
  previous_ = next;
  points_ = out.points_px;
  return out;
}

}  // namespace gvkit::facemap
