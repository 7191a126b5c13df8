#pragma once
// A textured head mesh of the ICT model as a scanner that exports meshes would give it, for tests
// and benchmarks of `facemap clean` on meshes: the face, head and neck, mouth and eye sockets
// (vertices 0-14061) as a triangle soup (quads split along the shorter diagonal), with vertex
// colours (per-region albedo), and the face and head & neck textured: per-corner texture
// coordinates into one image that holds the model's face UV tile in its left half and its head
// tile in its right half, with the albedo and Lambert shading baked in (as a photographic scan
// texture carries the light it was taken in). The sockets are untextured (their UVs overlap the
// head's). Exact ground truth: the landmark vertices.

#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/triangle_soup.hpp"

namespace gvkit::facemap {

struct SyntheticHeadOptions {
  int texture_px = 512;            // image height; the width is twice this
  cv::Vec3d light{0.2, 0.4, 1.0};  // model frame (+z out of the face, +y up), towards the light
  Status check() const;
};

struct SyntheticHead {
  TriangleSoup soup;                 // points in mm, one texture (textures[0]), path "head.png"
  std::vector<int> point_of_vertex;  // per model vertex its point index, -1 if not in the soup
  // Per landmark: the pixel of its vertex in the texture image (the vertex's face-tile UV).
  std::vector<cv::Point2f> landmark_pixels;
};

SyntheticHead synthetic_head_mesh(const IctFaceModel& model,
                                  const std::vector<cv::Vec3d>& positions_mm,
                                  const SyntheticHeadOptions& options = {});

}  // namespace gvkit::facemap
