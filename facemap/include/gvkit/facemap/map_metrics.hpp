#pragma once
// Mapping metrics of DESIGN.md section 6: distortion and flipped triangles of a map, feature
// drift of landmarks in the domain, and the drift of the true surface point seen by a fixed
// pixel when the ground-truth correspondence between frames is known.

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/mapped_face.hpp"

namespace gvkit::facemap {

// Distortion and flips of a per-triangle linear map: triangle k has corners xyz[3k + j] (mm)
// and image uv[3k + j] (px). Triangles with a non-finite image corner count as unmapped.
// orientation = +1 when a correctly oriented image triangle has positive signed area in uv,
// -1 when negative.
MapQuality measure_map_quality(const std::vector<Eigen::Vector3d>& xyz,
                               const std::vector<Eigen::Vector2d>& uv, int orientation);

struct DriftStats {
  int count = 0;
  double rms = 0, mean = 0, max = 0;
};

// Distances between the same landmarks (indices) in two frames' domains (px). Landmarks with a
// non-finite position are skipped.
DriftStats feature_drift(const std::vector<Eigen::Vector2d>& a,
                         const std::vector<Eigen::Vector2d>& b, const std::vector<int>& indices);

// For every pixel inside both frames' domain: the surface point frame a's pixel sampled, carried
// to frame b through the known correspondence (same vertex indices, positions_b_mm), against the
// point frame b's pixel sampled (mm).
DriftStats true_surface_drift(const MappedFace& a, const MappedFace& b,
                              const std::vector<cv::Vec3d>& positions_b_mm);

// Frame b's geometry image as a map without drift would sample it: every pixel of frame a's
// domain takes the surface point a's pixel sampled, carried to frame b through the known
// correspondence (same vertex indices, positions_b_mm). Same size as a's image, no texture; the
// mask is a's less the pixels without a sample of their own (filled from neighbours). The
// temporal block-matching error (block_matching.hpp) of such images is what the surface's own
// motion leaves in that metric for a map with a's layout and no drift at all.
GeometryImage carried_geometry_image(const MappedFace& a,
                                     const std::vector<cv::Vec3d>& positions_b_mm);

}  // namespace gvkit::facemap
