#pragma once
// A synthetic range scan of the ICT face for tests and benchmarks: an orthographic z-buffer
// render (camera looking at the face along the model's -z, OpenCV camera frame: x right, y down,
// z forward) with per-region albedo (skin, darker lips and brows, bright sclera, dark iris) and
// Lambert shading, so the texture looks like a face to a landmark detector. Ground-truth
// landmarks are the ICT landmark vertices projected into the image. Not a model of a real
// structured-light scanner (capture/ makes those); exact geometry and exact landmarks instead.

#include <map>
#include <string>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/range_scan.hpp"

namespace gvkit::facemap {

struct SyntheticFaceScanOptions {
  int size_px = 256;                // square image
  double pixel_mm = 0.8;            // orthographic pixel size
  double distance_mm = 700.0;       // camera z of the model's origin
  cv::Vec3d light{0.3, -0.5, 1.0};  // direction towards the light (model frame)
};

struct SyntheticFaceScan {
  RangeScan scan;           // valid on the face and head skin only (eyes and mouth are holes)
  FaceLandmarks landmarks;  // ground truth: points_px and points_mm (camera frame)
};

// Per vertex of the model: its albedo in [0, 1] by region (skin, dark mouth socket, bright
// sclera and teeth, dark iris), with darker lips and brows found from the landmark contours.
std::vector<double> ict_vertex_albedo(const IctFaceModel& model,
                                      const std::vector<cv::Vec3d>& positions_mm);

// Renders the model at the given vertex positions (model frame, mm; e.g. model.evaluate(...)).
SyntheticFaceScan render_synthetic_face_scan(const IctFaceModel& model,
                                             const std::vector<cv::Vec3d>& positions_mm,
                                             const SyntheticFaceScanOptions& options = {});

}  // namespace gvkit::facemap
