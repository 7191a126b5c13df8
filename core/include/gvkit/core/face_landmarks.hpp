#pragma once
// FaceLandmarks: the 68 points of the iBUG / Multi-PIE convention (dlib's numbering):
// jaw 0-16, brows 17-26, nose 27-35 (tip 30), eyes 36-41 (subject's right) and 42-47, outer lips
// 48-59, inner lips 60-67.

#include <vector>

#include <opencv2/core.hpp>

namespace gvkit {

struct FaceLandmarks {
  static constexpr int kCount = 68;
  static constexpr int kNoseTip = 30;
  std::vector<cv::Point2f> points_px;  // image pixels of the scan's texture; empty if unknown
  std::vector<cv::Vec3f> points_mm;    // 3D in the scan's frame (mm); empty if unknown
};

}  // namespace gvkit
