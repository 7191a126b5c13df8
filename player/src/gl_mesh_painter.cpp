#include "gl_mesh_painter.hpp"

#include <cmath>
#include <string>

namespace gvkit::player {
namespace {

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in float a_grey;
layout(location = 3) in float a_error;
uniform mat4 u_view_from_world;
uniform mat4 u_clip_from_view;
out vec3 v_position_view;
out vec3 v_normal_view;
out vec3 v_normal_world;
out float v_grey;
out float v_error;
void main() {
  vec4 p = u_view_from_world * vec4(a_position, 1.0);
  v_position_view = p.xyz;
  v_normal_view = mat3(u_view_from_world) * a_normal;
  v_normal_world = a_normal;
  v_grey = a_grey;
  v_error = a_error;
  gl_Position = u_clip_from_view * p;
}
)";

// Modes: 0 lit, 1 texture, 2 normals, 3 wireframe (lit), 4 error.
constexpr const char* kFragmentShader = R"(#version 330 core
in vec3 v_position_view;
in vec3 v_normal_view;
in vec3 v_normal_world;
in float v_grey;
in float v_error;
uniform int u_mode;
uniform int u_has_grey;
uniform int u_lines;
uniform float u_error_max;
out vec4 o_colour;

vec3 turbo(float t) {
  t = clamp(t, 0.0, 1.0);
  vec4 v4 = vec4(1.0, t, t * t, t * t * t);
  vec2 v2 = v4.zw * v4.z;
  return clamp(vec3(
    dot(v4, vec4(0.13572138, 4.61539260, -42.66032258, 132.13108234)) +
        dot(v2, vec2(-152.94239396, 59.28637943)),
    dot(v4, vec4(0.09140261, 2.19418839, 4.84296658, -14.18503333)) +
        dot(v2, vec2(4.27729857, 2.82956604)),
    dot(v4, vec4(0.10667330, 12.64194608, -60.58204836, 110.36276771)) +
        dot(v2, vec2(-89.90310912, 27.34824973))), 0.0, 1.0);
}

// Headlight plus a key light from the upper right, two-sided.
float shade(vec3 n, vec3 v) {
  vec3 key = normalize(vec3(0.4, 0.6, 0.7));
  float d = 0.55 * max(dot(n, key), 0.0) + 0.35 * max(dot(n, v), 0.0);
  float s = 0.25 * pow(max(dot(n, normalize(key + v)), 0.0), 48.0);
  return 0.18 + d + s;
}

void main() {
  if (u_lines == 1) {
    o_colour = vec4(0.12, 0.14, 0.18, 1.0);
    return;
  }
  vec3 v = normalize(-v_position_view);
  vec3 n = normalize(v_normal_view);
  bool flipped = dot(n, v) < 0.0;
  if (flipped) n = -n;
  float light = shade(n, v);
  vec3 base = vec3(0.55, 0.68, 0.85);
  vec3 c;
  if (u_mode == 1 && u_has_grey == 1) {
    c = vec3(v_grey) * (0.75 + 0.25 * light);
  } else if (u_mode == 2) {
    vec3 nw = normalize(v_normal_world);
    c = (flipped ? -nw : nw) * 0.5 + 0.5;
  } else if (u_mode == 4) {
    c = v_error < 0.0 ? vec3(0.6) * light
                      : turbo(v_error / u_error_max) * (0.55 + 0.45 * light);
  } else {
    c = base * light;
  }
  o_colour = vec4(clamp(c, 0.0, 1.0), 1.0);
}
)";

Result<GLuint> compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    glDeleteShader(shader);
    return Status(StatusCode::kInternal, std::string("shader compile failed: ") + log);
  }
  return shader;
}

void upload_floats(GLuint vbo, const std::vector<float>& data) {
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data.size() * sizeof(float)),
               data.empty() ? nullptr : data.data(), GL_DYNAMIC_DRAW);
}

}  // namespace

std::string gl_description() {
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  return std::string(renderer ? renderer : "?") + ", OpenGL " + (version ? version : "?");
}

Status gl_status(const char* what) {
  std::string codes;
  for (GLenum e = glGetError(); e != GL_NO_ERROR; e = glGetError()) {
    char buf[16];
    std::snprintf(buf, sizeof(buf), " 0x%04x", e);
    codes += buf;
  }
  if (codes.empty()) return Status::ok();
  return Status(StatusCode::kInternal, std::string(what) + ": OpenGL error" + codes);
}

Result<std::unique_ptr<GlMeshPainter>> GlMeshPainter::create() {
  std::unique_ptr<GlMeshPainter> p(new GlMeshPainter());
  GVKIT_ASSIGN_OR_RETURN(GLuint vs, compile(GL_VERTEX_SHADER, kVertexShader));
  auto fs_result = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  if (!fs_result.is_ok()) {
    glDeleteShader(vs);
    return fs_result.status();
  }
  const GLuint fs = *fs_result;
  p->program_ = glCreateProgram();
  glAttachShader(p->program_, vs);
  glAttachShader(p->program_, fs);
  glLinkProgram(p->program_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(p->program_, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetProgramInfoLog(p->program_, sizeof(log), nullptr, log);
    return Status(StatusCode::kInternal, std::string("shader link failed: ") + log);
  }
  p->u_view_ = glGetUniformLocation(p->program_, "u_view_from_world");
  p->u_clip_ = glGetUniformLocation(p->program_, "u_clip_from_view");
  p->u_mode_ = glGetUniformLocation(p->program_, "u_mode");
  p->u_error_max_ = glGetUniformLocation(p->program_, "u_error_max");
  p->u_has_grey_ = glGetUniformLocation(p->program_, "u_has_grey");
  p->u_lines_ = glGetUniformLocation(p->program_, "u_lines");

  glGenVertexArrays(1, &p->vao_);
  glBindVertexArray(p->vao_);
  GLuint buffers[5];
  glGenBuffers(5, buffers);
  p->position_vbo_ = buffers[0];
  p->normal_vbo_ = buffers[1];
  p->grey_vbo_ = buffers[2];
  p->error_vbo_ = buffers[3];
  p->index_ebo_ = buffers[4];
  const std::pair<GLuint, int> layout[] = {
      {p->position_vbo_, 3}, {p->normal_vbo_, 3}, {p->grey_vbo_, 1}, {p->error_vbo_, 1}};
  for (GLuint location = 0; location < 4; ++location) {
    glBindBuffer(GL_ARRAY_BUFFER, layout[location].first);
    glVertexAttribPointer(location, layout[location].second, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnableVertexAttribArray(location);
  }
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, p->index_ebo_);
  glBindVertexArray(0);
  GVKIT_RETURN_IF_ERROR(gl_status("mesh painter setup"));
  return p;
}

GlMeshPainter::~GlMeshPainter() {
  const GLuint buffers[] = {position_vbo_, normal_vbo_, grey_vbo_, error_vbo_, index_ebo_};
  glDeleteBuffers(5, buffers);
  glDeleteVertexArrays(1, &vao_);
  glDeleteProgram(program_);
}

void GlMeshPainter::upload(const MeshBuffers& mesh) {
  vertex_count_ = mesh.vertex_count();
  index_count_ = mesh.indices.size();
  has_grey_ = !mesh.grey.empty();
  glBindVertexArray(vao_);
  upload_floats(position_vbo_, mesh.positions_mm);
  upload_floats(normal_vbo_, mesh.normals);
  upload_floats(grey_vbo_, has_grey_ ? mesh.grey : std::vector<float>(vertex_count_, 0.8f));
  upload_floats(error_vbo_, std::vector<float>(vertex_count_, -1.0f));
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(index_count_ * sizeof(uint32_t)),
               mesh.indices.empty() ? nullptr : mesh.indices.data(), GL_DYNAMIC_DRAW);
  glBindVertexArray(0);
}

void GlMeshPainter::upload_errors(const std::vector<float>& errors_mm) {
  GVKIT_CHECK(errors_mm.size() == vertex_count_, "one error per vertex");
  std::vector<float> e(errors_mm);
  for (float& x : e)
    if (!std::isfinite(x)) x = -1.0f;  // no reference: drawn grey
  upload_floats(error_vbo_, e);
}

void GlMeshPainter::draw(const Eigen::Matrix4f& view_from_world,
                         const Eigen::Matrix4f& clip_from_view, const DrawStyle& style) {
  if (index_count_ == 0) return;
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glUseProgram(program_);
  glUniformMatrix4fv(u_view_, 1, GL_FALSE, view_from_world.data());
  glUniformMatrix4fv(u_clip_, 1, GL_FALSE, clip_from_view.data());
  glUniform1i(u_mode_, static_cast<int>(style.mode));
  glUniform1i(u_has_grey_, has_grey_ ? 1 : 0);
  glUniform1f(u_error_max_, style.error_max_mm > 0 ? style.error_max_mm : 1.0f);
  glUniform1i(u_lines_, 0);
  glBindVertexArray(vao_);
  const bool wire = style.mode == ShadingMode::kWireframe;
  if (wire) {
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 1.0f);
  }
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(index_count_), GL_UNSIGNED_INT, nullptr);
  if (wire) {
    glDisable(GL_POLYGON_OFFSET_FILL);
    glUniform1i(u_lines_, 1);
    glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(index_count_), GL_UNSIGNED_INT, nullptr);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  }
  glBindVertexArray(0);
  glUseProgram(0);
}

}  // namespace gvkit::player
