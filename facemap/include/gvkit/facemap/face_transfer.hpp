#pragma once
// Carrying one frame's cleaned face to other frames of a registered sequence (every input mesh
// has the same vertex layout: same vertex count and the same triangles): each vertex and
// landmark of the reference frame's cleaned face is anchored on the reference input surface
// (triangle + barycentric of its closest point, plus the offset to it for points off the input
// surface, e.g. in filled holes), and evaluated on the other frame's input mesh. All frames then
// share the cleaned vertex layout, so a map's pixels can be followed to fixed surface points
// (`facemap map --same-vertices`), and the eye and mouth cuts follow the same skin points.

#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/face_cleaning.hpp"

namespace gvkit::facemap {

struct SurfaceAnchor {
  int face = -1;                        // triangle of the surface
  std::array<double, 3> barycentric{};  // of the closest point, in the face's vertex order
  cv::Vec3d offset_mm{0, 0, 0};         // point minus its closest point (mesh frame)
};

// The closest point of `surface` to each of `points_mm` (nearest vertex by a uniform grid, then
// the triangles of its two-ring). Fails on a surface without triangles.
Result<std::vector<SurfaceAnchor>> anchor_points(const Mesh& surface,
                                                 const std::vector<cv::Vec3d>& points_mm);
// The anchored point on `surface` (same layout as the one anchored on): barycentric combination
// of the face's corners plus the offset.
cv::Vec3d evaluate_anchor(const Mesh& surface, const SurfaceAnchor& anchor);

struct TransferStats {
  int off_surface_vertices = 0;  // reference vertices farther than 1e-6 mm from the input
  double max_offset_mm = 0.0;
};

// `reference` (cleaned from `reference_input`) carried to `target_input`. Fails naming `name`
// when the target's layout differs from the reference input's.
Result<CleanedFace> transfer_cleaned_face(const CleanedFace& reference, const Mesh& reference_input,
                                          const Mesh& target_input, const std::string& name,
                                          TransferStats* stats = nullptr);

}  // namespace gvkit::facemap
