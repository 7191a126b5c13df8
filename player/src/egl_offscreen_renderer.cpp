// The offscreen Renderer: an EGL OpenGL 3.3 core context without any surface, drawing into a
// framebuffer object (multisampled, resolved by a blit) and reading the pixels back.
#include <cstdio>
#include <string>

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <opencv2/imgproc.hpp>

#include "gl_mesh_painter.hpp"
#include "gvkit/player/colormap.hpp"
#include "gvkit/player/renderer.hpp"

namespace gvkit::player {
namespace {

std::string egl_error(const char* what) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "%s failed (EGL error 0x%04x)", what, eglGetError());
  return buf;
}

bool has_extension(const char* list, const char* name) {
  if (!list) return false;
  const std::string all = std::string(" ") + list + " ";
  return all.find(std::string(" ") + name + " ") != std::string::npos;
}

// Displays to try, best first: Mesa's surfaceless platform, the first EGL device, the default.
std::vector<EGLDisplay> candidate_displays() {
  std::vector<EGLDisplay> out;
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (has_extension(client, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay d =
        eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (d != EGL_NO_DISPLAY) out.push_back(d);
  }
  if (has_extension(client, "EGL_EXT_platform_device") &&
      has_extension(client, "EGL_EXT_device_enumeration")) {
    EGLDeviceEXT devices[4];
    EGLint count = 0;
    if (eglQueryDevicesEXT(4, devices, &count) && count > 0) {
      EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[0], nullptr);
      if (d != EGL_NO_DISPLAY) out.push_back(d);
    }
  }
  EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
  if (d != EGL_NO_DISPLAY) out.push_back(d);
  return out;
}

class EglOffscreenRenderer : public Renderer {
 public:
  static Result<std::unique_ptr<Renderer>> make(const RenderOptions& options) {
    std::unique_ptr<EglOffscreenRenderer> r(new EglOffscreenRenderer(options));
    GVKIT_RETURN_IF_ERROR(r->init_context());
    GVKIT_RETURN_IF_ERROR(r->init_framebuffers());
    GVKIT_ASSIGN_OR_RETURN(r->painter_, GlMeshPainter::create());
    return std::unique_ptr<Renderer>(std::move(r));
  }

  ~EglOffscreenRenderer() override {
    if (context_ != EGL_NO_CONTEXT) {
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_);
      painter_.reset();
      const GLuint fbos[] = {draw_fbo_, resolve_fbo_};
      glDeleteFramebuffers(2, fbos);
      const GLuint rbos[] = {colour_rb_, depth_rb_, resolve_rb_};
      glDeleteRenderbuffers(3, rbos);
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display_, context_);
    }
    // The display is not terminated: EGL displays are shared per process, so eglTerminate would
    // also end the contexts of other renderers; the driver stays loaded until exit.
  }

  void set_mesh(const MeshBuffers& mesh) override {
    make_current();
    painter_->upload(mesh);
  }

  void set_vertex_errors(const std::vector<float>& errors_mm) override {
    make_current();
    painter_->upload_errors(errors_mm);
  }

  Result<cv::Mat> render(const ViewCamera& camera, const DrawStyle& style) override {
    make_current();
    glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
    glViewport(0, 0, options_.width, options_.height);
    glClearColor(kBackgroundRgb[0], kBackgroundRgb[1], kBackgroundRgb[2], 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    painter_->draw(camera.view_from_world(),
                   camera.clip_from_view(static_cast<double>(options_.width) / options_.height),
                   style);
    GLuint read_fbo = draw_fbo_;
    if (resolve_fbo_) {
      glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_fbo_);
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_);
      glBlitFramebuffer(0, 0, options_.width, options_.height, 0, 0, options_.width,
                        options_.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
      read_fbo = resolve_fbo_;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, read_fbo);
    cv::Mat rgba(options_.height, options_.width, CV_8UC4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, options_.width, options_.height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    GVKIT_RETURN_IF_ERROR(gl_status("offscreen render"));
    cv::Mat bgr;
    cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
    cv::flip(bgr, bgr, 0);  // GL rows run bottom-up
    if (style.mode == ShadingMode::kError && style.colour_bar)
      draw_colour_bar(bgr, style.error_max_mm, style.error_title);
    return bgr;
  }

  std::string description() const override { return description_; }

 private:
  explicit EglOffscreenRenderer(const RenderOptions& options) : options_(options) {}

  void make_current() {
    if (eglGetCurrentContext() != context_)
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_);
  }

  Status init_context() {
    std::string errors;
    auto note = [&errors](const std::string& what) {
      errors.append(" ");
      errors.append(what);
      errors.append(";");
    };
    for (EGLDisplay d : candidate_displays()) {
      EGLint major = 0, minor = 0;
      if (!eglInitialize(d, &major, &minor)) {
        note(egl_error("eglInitialize"));
        continue;
      }
      const char* ext = eglQueryString(d, EGL_EXTENSIONS);
      if (!has_extension(ext, "EGL_KHR_surfaceless_context") || !eglBindAPI(EGL_OPENGL_API)) {
        note("display without surfaceless OpenGL");
        eglTerminate(d);
        continue;
      }
      EGLConfig config = EGL_NO_CONFIG_KHR;
      if (!has_extension(ext, "EGL_KHR_no_config_context") &&
          !has_extension(ext, "EGL_MESA_configless_context")) {
        const EGLint attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLint n = 0;
        if (!eglChooseConfig(d, attribs, &config, 1, &n) || n < 1) {
          note(egl_error("eglChooseConfig"));
          eglTerminate(d);
          continue;
        }
      }
      const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                        3,
                                        EGL_CONTEXT_MINOR_VERSION,
                                        3,
                                        EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                        EGL_NONE};
      EGLContext c = eglCreateContext(d, config, EGL_NO_CONTEXT, context_attribs);
      if (c == EGL_NO_CONTEXT) {
        note(egl_error("eglCreateContext (OpenGL 3.3 core)"));
        eglTerminate(d);
        continue;
      }
      if (!eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, c)) {
        note(egl_error("eglMakeCurrent"));
        eglDestroyContext(d, c);
        eglTerminate(d);
        continue;
      }
      display_ = d;
      context_ = c;
      description_ = gl_description();
      return Status::ok();
    }
    return Status(StatusCode::kUnsupported,
                  "no offscreen OpenGL 3.3 context through EGL:" +
                      (errors.empty() ? std::string(" no EGL display") : errors));
  }

  Status init_framebuffers() {
    const int w = options_.width, h = options_.height;
    GLint max_samples = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    const int samples = std::min(options_.msaa_samples, static_cast<int>(max_samples));
    auto storage = [&](GLenum format) {
      if (samples > 0)
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, w, h);
      else
        glRenderbufferStorage(GL_RENDERBUFFER, format, w, h);
    };
    glGenFramebuffers(1, &draw_fbo_);
    glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
    glGenRenderbuffers(1, &colour_rb_);
    glBindRenderbuffer(GL_RENDERBUFFER, colour_rb_);
    storage(GL_RGBA8);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_rb_);
    glGenRenderbuffers(1, &depth_rb_);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_rb_);
    storage(GL_DEPTH_COMPONENT24);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rb_);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      return Status(StatusCode::kUnsupported, "offscreen framebuffer incomplete");
    if (samples > 0) {
      glGenFramebuffers(1, &resolve_fbo_);
      glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_);
      glGenRenderbuffers(1, &resolve_rb_);
      glBindRenderbuffer(GL_RENDERBUFFER, resolve_rb_);
      glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_rb_);
      if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return Status(StatusCode::kUnsupported, "offscreen resolve framebuffer incomplete");
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return gl_status("offscreen framebuffer setup");
  }

  RenderOptions options_;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  GLuint draw_fbo_ = 0, resolve_fbo_ = 0, colour_rb_ = 0, depth_rb_ = 0, resolve_rb_ = 0;
  std::unique_ptr<GlMeshPainter> painter_;
  std::string description_;
};

}  // namespace

Status RenderOptions::check() const {
  if (width < 16 || height < 16 || width > 8192 || height > 8192)
    return invalid_argument("render size must be between 16x16 and 8192x8192, got " +
                            std::to_string(width) + "x" + std::to_string(height));
  if (msaa_samples < 0 || msaa_samples > 16)
    return invalid_argument("msaa samples must be in 0..16");
  return Status::ok();
}

Result<std::unique_ptr<Renderer>> Renderer::create(const RenderOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  return EglOffscreenRenderer::make(options);
}

}  // namespace gvkit::player
