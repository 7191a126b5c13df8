#pragma once
// Triangle mesh of a range scan: the camera-pixel grid over valid pixels, two triangles per
// 2x2 block of valid pixels (split along the shorter diagonal), one where only three are valid.
// Triangles across depth discontinuities are skipped: an edge is cut when it is longer than
// max_edge_factor times the pixel footprint at its depth (the footprint per mm of depth is
// estimated from the scan itself as the median neighbour spacing / depth, so no calibration is
// needed). Vertex colour = texture (grey); only the largest connected component is kept.

#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/mesh.hpp"
#include "gvkit/core/range_scan.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/mesh_repair.hpp"

namespace gvkit::facemap {

struct MeshFromScanOptions {
  // An edge is a discontinuity when longer than 1.5 x this many pixel footprints (1.5 leaves room
  // for diagonals). 4 keeps surfaces up to about 80 degrees from facing the camera.
  double max_edge_factor = 4.0;
  bool keep_largest_component = true;
  Status check() const;
};

struct ScanMesh {
  Mesh mesh;                            // mm, camera frame, vertex colours = texture
  std::vector<cv::Point> vertex_pixel;  // per vertex: its scan pixel (x = column, y = row)
  cv::Mat vertex_of_pixel;              // CV_32S, scan size: vertex index or -1
  double footprint_per_depth = 0.0;     // pixel footprint (mm) per mm of depth
  MeshRepairReport repair;              // components, refused faces
};

// Fails (failed precondition, naming the frame index) when the scan has fewer than 3 valid
// pixels or no triangle survives; the scan must pass RangeScan::check().
Result<ScanMesh> mesh_from_scan(const RangeScan& scan, const MeshFromScanOptions& options = {});
// The same into `out` (no copy of the mesh).
Status mesh_from_scan(const RangeScan& scan, const MeshFromScanOptions& options, ScanMesh* out);

}  // namespace gvkit::facemap
