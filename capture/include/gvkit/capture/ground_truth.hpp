#pragma once
// Ground truth of a synthetic frame, per camera pixel, as one OpenEXR file
// (gt/frame_NNNNNN.exr, documented in docs/session-format.md):
//   X, Y, Z     surface point seen by the pixel, camera frame (mm); NaN where no surface
//   F           index of the mesh polygon (the ICT model's OBJ face, 0-based) seen; -1 = none
//   V0, V1, V2  model vertex indices of the triangle seen (of polygon F); -1 = none
//   B0, B1, B2  barycentric weights of V0, V1, V2 (sum 1): point = B0*P[V0] + B1*P[V1] + B2*P[V2]
//   L           1 where the point is also lit by the projector (not in shadow), else 0
// Indices are stored as floats: exact below 2^24.

#include <filesystem>

#include <opencv2/core.hpp>

#include "gvkit/capture/synthetic_renderer.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

struct GroundTruth {
  cv::Mat xyz_mm;       // CV_32FC3
  cv::Mat polygon;      // CV_32S, -1 = none
  cv::Mat vertices;     // CV_32SC3, -1 = none
  cv::Mat barycentric;  // CV_32FC3
  cv::Mat lit;          // CV_8U, 255 = lit
};

// Converts a renderer's truth using the scene's triangles (triangle_source -> polygon index).
GroundTruth ground_truth_of(const SyntheticTruth& truth, const SyntheticScene& scene);

Status write_ground_truth_exr(const std::filesystem::path& path, const GroundTruth& truth);
// Fails naming the file when it is missing, unreadable or lacks a channel.
Result<GroundTruth> read_ground_truth_exr(const std::filesystem::path& path);

}  // namespace gvkit::capture
