#pragma once
// Two cameras and an uncalibrated projector: the projector only labels surface points (each
// camera decodes the absolute projector column u it sees), and depth comes from the camera pair.
// Both phase maps are rectified (cv::stereoRectify, or the rectification the calibration file
// holds), each left pixel's u is found along its rectified row in the right map at sub-pixel
// precision (linear interpolation between the two right pixels whose u brackets it), and the
// disparity is triangulated with Q. The scan lies on the left camera's own pixel grid (its
// texture is the left images'), its points in the left camera frame (mm).

#include <opencv2/core.hpp>

#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/core/calibration_io.hpp"
#include "gvkit/core/fringe_set.hpp"
#include "gvkit/core/range_scan.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

// A calibrated camera pair (OpenCV stereo_calib's M1 D1 M2 D2 R T: X_right = R X_left + T).
struct StereoCalibration {
  cv::Matx33d left_K = cv::Matx33d::eye(), right_K = cv::Matx33d::eye();
  std::vector<double> left_dist, right_dist;
  cv::Size size;  // both cameras' image size (px)
  cv::Matx33d R_right_from_left = cv::Matx33d::eye();
  cv::Vec3d t_right_from_left_mm{0, 0, 0};
  cv::Mat R1, R2, P1, P2, Q;  // the file's rectification, or empty (computed)

  // Ok when the matrices are finite, focal lengths positive, R a rotation and the baseline
  // non-zero; else says which is wrong.
  Status check() const;
};

// The pair from a two-device calibration (read_two_device_calibration); its sizes, when
// recorded, must equal `image_size`.
Result<StereoCalibration> stereo_calibration(const TwoDeviceCalibration& devices,
                                             cv::Size image_size);

struct StereoOptions {
  double min_depth_mm = 50, max_depth_mm = 20000;  // points outside are invalid
  // Projector width the patterns are decoded for; only the scale of the matched coordinate u
  // (pattern sets with a pitch in projector pixels need the real one).
  int projector_width = 1024;
  Status check() const;
};

class StereoReconstructor {
 public:
  // Rectifies the pair once (maps for the right camera, rectified coordinates of every left
  // pixel). Fails when the calibration does not check.
  static Result<StereoReconstructor> create(const StereoCalibration& calibration,
                                            const StereoOptions& options = {});

  // Decodes both image sets and matches them. The pattern set must give absolute phase
  // (multi-frequency, heterodyne, Gray code): a spatially unwrapped phase differs between the
  // cameras by unknown whole periods. Fails naming the camera on a decoding failure or images of
  // another size than the calibration's.
  Result<RangeScan> reconstruct(const FringeSet& left, const FringeSet& right,
                                const PatternSet& patterns) const;
  // Matches two decoded maps (absolute, calibration size).
  RangeScan match(const PhaseMap& left, const PhaseMap& right) const;

  const StereoCalibration& calibration() const { return calibration_; }

 private:
  StereoReconstructor() = default;

  StereoCalibration calibration_;
  StereoOptions options_;
  cv::Mat right_map_x_, right_map_y_;  // rectified right pixel -> original right pixel
  cv::Mat left_rectified_;             // CV_32FC2: original left pixel -> rectified (x, y)
  cv::Matx33d R1_;                     // rectified-left from left
  cv::Matx44d Q_;
};

}  // namespace gvkit::capture
