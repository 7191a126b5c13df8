#pragma once
// The facial features facemap works with, derived from the 68 landmarks (dlib numbering): the two
// eye contours, the mouth contour and the nose tip; and the lifting of image landmarks to 3D
// through a range scan.

#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/mesh.hpp"
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

// What lift_landmarks did: how many required landmarks fell on no usable pixel (an open mouth's
// inner lip over the mouth interior, an eye contour over a removed eyeball) and took the nearest
// usable one, and the largest such move.
struct LandmarkLiftReport {
  int snapped = 0;
  double max_snap_px = 0.0;
};

// Fills landmarks->points_mm from points_px: bilinear in the scan's xyz where the four pixels are
// usable, else the nearest usable pixel. Usable pixels are `usable` (CV_8U, scan size, non-zero =
// usable; e.g. the pixels of the kept mesh) or scan.valid when empty. Fails (failed precondition)
// naming the landmark and its pixel when a required landmark lies more than max_distance_px from
// any usable pixel or outside the image.
Status lift_landmarks(const RangeScan& scan, FaceLandmarks* landmarks, double max_distance_px = 3.0,
                      const cv::Mat& usable = cv::Mat(), LandmarkLiftReport* report = nullptr);

// Pixels of the scan that are seen through the open mouth or the eye openings: farther than
// min_inside_px inside the inner lip contour (60-67) or an eye contour (36-41, 42-47) of
// landmarks.points_px. They are not skin (teeth, tongue, mouth interior, eyeballs), so the clean
// stage leaves them out of the mesh; a closed mouth or eye (a degenerate contour) removes nothing.
// Returns valid with those pixels cleared (a new matrix) and their count in *removed.
cv::Mat valid_without_feature_interiors(const RangeScan& scan, const FaceLandmarks& landmarks,
                                        double min_inside_px = 0.5, int* removed = nullptr);

// A hole of a mesh inside an eye or mouth opening (the part of the face the mask removes): one
// of its boundary halfedges and its feature, 0 right eye, 1 left eye, 2 mouth.
struct FeatureHole {
  Mesh::HalfedgeHandle halfedge;
  int feature = 0;
};

// The boundary loops of a scan's mesh that lie inside an eye contour (36-41, 42-47) or the inner
// lip contour (60-67) of landmarks.points_px: every vertex's pixel (`vertex_pixel`, by vertex
// index) at most max_outside_px + max_outside_fraction x half the contour's larger bounding-box
// side outside the contour polygon (the lids and lips are curves that bulge out of the polygon
// of their landmarks). These are the openings that valid_without_feature_interiors cut or that
// the scan leaves there (an eye seen as a gap); a loop that reaches farther out (an opening
// merged with a gap of the scan) is not one, nor one of fewer than min_edges edges (a missing
// pixel: its fill is free). One entry per loop. The face mask checks that its contour path
// encloses each of them.
std::vector<FeatureHole> feature_interior_holes(
    const Mesh& mesh, const std::vector<cv::Point>& vertex_pixel, const FaceLandmarks& landmarks,
    double max_outside_px = 2.0, double max_outside_fraction = 0.25, int min_edges = 12);

// Centroid (mm) of the given landmarks' points_mm.
cv::Vec3d landmark_centroid(const FaceLandmarks& landmarks, const int* begin, const int* end);

}  // namespace gvkit::facemap
