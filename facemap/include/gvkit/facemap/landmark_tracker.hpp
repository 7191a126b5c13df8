#pragma once
// LandmarkTracker: follows the 68 landmarks from frame to frame on the scans' textures with
// pyramidal Lucas-Kanade optical flow (OpenCV), checked forward-backward. When too many points
// are lost, it re-detects with the LandmarkDetector (if it has one). Frames must come in order.

#include <optional>

#include <opencv2/core.hpp>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/landmark_detector.hpp"

namespace gvkit::facemap {

struct LandmarkTrackerOptions {
  int window_px = 21;  // LK window side
  int pyramid_levels = 3;
  double max_forward_backward_px = 1.0;  // a point is lost beyond this round-trip error
  double max_lost_fraction = 0.1;        // re-detect (or fail) when more points are lost
  Status check() const;
};

class LandmarkTracker {
 public:
  // `first` holds points_px on `first_image` (CV_32F in [0, 1] or CV_8U). detector may be null
  // (no re-detection) and must outlive the tracker.
  LandmarkTracker(const cv::Mat& first_image, const FaceLandmarks& first,
                  const LandmarkDetector* detector, const LandmarkTrackerOptions& options = {});

  // Landmarks (points_px) on the next image. Fails (failed precondition) when tracking is lost
  // and re-detection is impossible or finds no face.
  Result<FaceLandmarks> track(const cv::Mat& image);
  int redetections() const { return redetections_; }

 private:
  cv::Mat previous_;
  std::vector<cv::Point2f> points_;
  const LandmarkDetector* detector_;
  LandmarkTrackerOptions options_;
  int redetections_ = 0;
};

}  // namespace gvkit::facemap
