#pragma once
// GlMeshPainter (internal): the OpenGL 3.3 core drawing shared by the offscreen renderer and the
// window. Owns the shader program and the mesh buffers; needs the same current context for its
// whole life, including the destructor.

#include <memory>
#include <vector>

#include <epoxy/gl.h>
#include <Eigen/Core>

#include "gvkit/core/status.hpp"
#include "gvkit/player/geometry_image_mesh.hpp"
#include "gvkit/player/renderer.hpp"

namespace gvkit::player {

class GlMeshPainter {
 public:
  // Compiles the shaders; fails with the compiler log.
  static Result<std::unique_ptr<GlMeshPainter>> create();
  ~GlMeshPainter();
  GlMeshPainter(const GlMeshPainter&) = delete;
  GlMeshPainter& operator=(const GlMeshPainter&) = delete;

  void upload(const MeshBuffers& mesh);
  void upload_errors(const std::vector<float>& errors_mm);
  // Draws into the bound framebuffer's current viewport (depth test on, no clear).
  void draw(const Eigen::Matrix4f& view_from_world, const Eigen::Matrix4f& clip_from_view,
            const DrawStyle& style);
  size_t vertex_count() const { return vertex_count_; }

 private:
  GlMeshPainter() = default;
  GLuint program_ = 0, vao_ = 0;
  GLuint position_vbo_ = 0, normal_vbo_ = 0, grey_vbo_ = 0, error_vbo_ = 0, index_ebo_ = 0;
  GLint u_view_ = -1, u_clip_ = -1, u_mode_ = -1, u_error_max_ = -1, u_has_grey_ = -1,
        u_lines_ = -1;
  size_t vertex_count_ = 0, index_count_ = 0;
  bool has_grey_ = false;
};

// "GL_RENDERER, GL_VERSION" of the current context.
std::string gl_description();
// Ok, or the pending glGetError codes named with `what`.
Status gl_status(const char* what);

}  // namespace gvkit::player
