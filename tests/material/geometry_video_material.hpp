#pragma once
// Geometry videos for testing and measuring the codec before facemap exists:
// - the ICT face (vertices 0..9408, which fill UV tile [0,1]^2) animated by blendshape weights
//   that vary smoothly over time, rasterized into its own UV layout (v up), positions in mm;
// - a smooth analytic surface (a breathing bump with ripples) on an elliptic domain with a hole.

#include <filesystem>
#include <vector>

#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::testing {

struct GeometryVideoOptions {
  int size = 320;  // width = height (pixels)
  int frames = 60;
  double fps = 30.0;
};

// Loads the ICT model from ict_dir (e.g. ../shared/data/ict-facekit) with the expressions it
// animates. Fails naming the file when the model cannot be read.
Result<std::vector<GeometryImage>> make_ict_face_video(const std::filesystem::path& ict_dir,
                                                       const GeometryVideoOptions& options);

std::vector<GeometryImage> make_analytic_video(const GeometryVideoOptions& options);

// make_analytic_video (size x size, `frames` frames) moving by (0.75, 0.375) pixels per frame
// and growing by 1 % per frame about its centre (so that x, y and z change together).
std::vector<GeometryImage> make_moving_analytic_video(int size, int frames);

// Real motion in the picture: warps frame f's xyz (bicubic, edges replicated) so that its
// content moves by (-shift_px f, -shift_px f / 2) pixels and is scaled by 1 + scale_per_frame f
// about the picture's centre. The texture and the domain mask stay as they are.
void move_in_picture(std::vector<GeometryImage>* video, double shift_px,
                     double scale_per_frame = 0.0);

}  // namespace gvkit::testing
