#pragma once
// The facial features facemap works with, derived from the 68 landmarks (dlib numbering): the two
// eye contours, the mouth contour and the nose tip; and the lifting of image landmarks to 3D
// through a range scan.

#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/range_scan.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

inline constexpr std::array<int, 6> kRightEyeContour{36, 37, 38, 39, 40, 41};  // subject's right
inline constexpr std::array<int, 6> kLeftEyeContour{42, 43, 44, 45, 46, 47};
inline constexpr std::array<int, 12> kOuterMouthContour{48, 49, 50, 51, 52, 53,
                                                        54, 55, 56, 57, 58, 59};
inline constexpr std::array<int, 8> kInnerMouthContour{60, 61, 62, 63, 64, 65, 66, 67};

enum class MouthContour { kInner, kOuter };

// Landmark indices facemap needs in 3D: the nose tip, both eyes and the whole mouth.
std::vector<int> required_landmarks();

// Fills landmarks->points_mm from points_px: bilinear in the scan's xyz where the four pixels are
// valid, else the nearest valid pixel. Fails (failed precondition) naming the landmark and its
// pixel when a required landmark lies more than max_distance_px from any valid pixel or outside
// the image.
Status lift_landmarks(const RangeScan& scan, FaceLandmarks* landmarks,
                      double max_distance_px = 3.0);

// Centroid (mm) of the given landmarks' points_mm.
cv::Vec3d landmark_centroid(const FaceLandmarks& landmarks, const int* begin, const int* end);

}  // namespace gvkit::facemap
