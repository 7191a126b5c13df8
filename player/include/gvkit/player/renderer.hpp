#pragma once
// Renderer: draws a geometry-image mesh with one of the shading modes and returns the picture.
// create() gives the offscreen OpenGL 3.3 renderer on EGL (Mesa surfaceless or device platform,
// no display needed; llvmpipe works). Only built with GVKIT_WITH_PLAYER.

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/status.hpp"
#include "gvkit/player/geometry_image_mesh.hpp"
#include "gvkit/player/shading_mode.hpp"
#include "gvkit/player/view_camera.hpp"

namespace gvkit::player {

struct RenderOptions {
  int width = 640, height = 480;  // picture size (px), 16..8192
  int msaa_samples = 4;           // 0 = no multisampling; 1..16
  Status check() const;
};

struct DrawStyle {
  ShadingMode mode = ShadingMode::kLit;
  float error_max_mm = 1.0f;  // kError: the top of the colour scale (> 0)
  bool colour_bar = true;     // kError: draw the colour bar into the picture
  // kError: the colour bar's title, naming what the per-vertex values are and their unit (e.g.
  // "normal error (deg)" when set_vertex_errors was given angles; error_max_mm is then in the
  // same unit).
  std::string error_title = "error (mm)";
};

// Background and surface colours shared by every renderer (RGB in [0, 1]).
inline constexpr float kBackgroundRgb[3] = {0.97f, 0.97f, 0.98f};

class Renderer {
 public:
  virtual ~Renderer() = default;
  // The offscreen renderer. Fails with the EGL/GL error when no OpenGL 3.3 core context can be
  // made, or when options fail check().
  static Result<std::unique_ptr<Renderer>> create(const RenderOptions& options);

  // The mesh to draw from now on (uploaded now).
  virtual void set_mesh(const MeshBuffers& mesh) = 0;
  // Per-vertex errors (mm) for kError, one per vertex of the current mesh (contract); NaN or
  // negative = no reference there (drawn grey).
  virtual void set_vertex_errors(const std::vector<float>& errors_mm) = 0;
  // Draws and reads back: CV_8UC3 BGR of the options' size, top row first. Fails on a GL error.
  virtual Result<cv::Mat> render(const ViewCamera& camera, const DrawStyle& style) = 0;
  // "Mesa ... llvmpipe ..." — the GL_RENDERER and GL_VERSION strings.
  virtual std::string description() const = 0;
};

}  // namespace gvkit::player
