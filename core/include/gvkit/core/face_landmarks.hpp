#pragma once
// FaceLandmarks: the 68 points of the iBUG / Multi-PIE convention (dlib's numbering):
// jaw 0-16, brows 17-26, nose 27-35 (tip 30), eyes 36-41 (subject's right) and 42-47, outer lips
// 48-59, inner lips 60-67. Landmarks from a 51-point set (the same numbering without the jaw)
// have NaN coordinates at 0-16: only the jaw may be absent; what facemap needs (the nose tip,
// eyes and lips, 30 and 36-67) is always there. The chin (8) when present, else the lower lip's
// middle (57), gives the face's downward direction.

#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

namespace gvkit {

struct FaceLandmarks {
  static constexpr int kCount = 68;
  static constexpr int kNoseTip = 30;
  static constexpr int kJawCount = 17;  // points 0-16, absent (NaN) in 51-point sets
  static constexpr int kChin = 8;
  static constexpr int kLowerLipMiddle = 57;
  std::vector<cv::Point2f> points_px;  // image pixels of the scan's texture; empty if unknown
  std::vector<cv::Vec3f> points_mm;    // 3D in the scan's frame (mm); empty if unknown

  // The chin's 3-D point, else (a 51-point set) the lower lip's middle: a point below the nose
  // tip on the face's vertical midline, for the face's downward direction. Needs 68 points_mm.
  const cv::Vec3f& chin_or_lower_lip_mm() const {
    const cv::Vec3f& chin = points_mm[kChin];
    return std::isfinite(chin[0]) ? chin : points_mm[kLowerLipMiddle];
  }
};

}  // namespace gvkit
