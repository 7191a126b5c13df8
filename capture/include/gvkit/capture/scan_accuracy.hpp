#pragma once
// Accuracy of a RangeScan against synthetic ground truth (DESIGN.md section 6: RMS and max
// depth error in mm, share of valid pixels).

#include <cstdint>

#include "gvkit/capture/ground_truth.hpp"
#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/range_scan.hpp"

namespace gvkit::capture {

struct ScanAccuracy {
  int64_t compared_px = 0;  // valid in the scan and a surface in the truth
  double rms_mm = 0, max_mm = 0, p50_mm = 0, p99_mm = 0;  // |z - z_true|, compared pixels
  // Face interior: lit pixels on the face area whose 8 neighbours are lit face pixels too (no
  // silhouette or shadow edge, where one pixel mixes two surfaces).
  int64_t face_interior_px = 0;
  double face_interior_valid_share = 0;  // of those pixels, the share the scan measured
  double face_interior_rms_mm = 0, face_interior_max_mm = 0;
};

// Contract: scan and truth have one size. A face pixel sees a triangle whose three vertices are
// below face_vertex_count.
ScanAccuracy scan_accuracy(const RangeScan& scan, const GroundTruth& truth,
                           int face_vertex_count = IctFaceModel::kFaceVertexCount);

}  // namespace gvkit::capture
