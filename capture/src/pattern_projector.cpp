#include "gvkit/capture/pattern_projector.hpp"

#include <epoxy/gl.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>

#include <opencv2/imgproc.hpp>

#include "gvkit/core/gl_driver_modules.hpp"

namespace gvkit {
namespace {

// GLFW reports errors through a callback; keep the last one for the Status message.
std::mutex error_mutex;
std::string last_glfw_error;

void on_glfw_error(int code, const char* description) {
  std::lock_guard<std::mutex> lock(error_mutex);
  last_glfw_error = description ? description : ("GLFW error " + std::to_string(code));
}

std::string take_glfw_error() {
  std::lock_guard<std::mutex> lock(error_mutex);
  std::string e = last_glfw_error.empty() ? std::string("unknown GLFW error") : last_glfw_error;
  last_glfw_error.clear();
  return e;
}

}  // namespace

Status PatternProjectorOptions::check() const {
  if (monitor < 0)
    return invalid_argument("projector: monitor " + std::to_string(monitor) + " is negative");
  if (window_width < 0 || window_height < 0 || window_width > 16384 || window_height > 16384)
    return invalid_argument("projector: window size " + std::to_string(window_width) + "x" +
                            std::to_string(window_height) + " is outside 0..16384");
  return Status::ok();
}

struct PatternProjector::Impl {
  GLFWwindow* window = nullptr;
  std::string monitor_name;
  int monitor_index = 0;
  bool fullscreen = false;
  double refresh = 0;
  int width = 0, height = 0;
  std::vector<GLuint> textures, framebuffers;
  cv::Size pattern_size;

  ~Impl() {
    if (window) {
      glfwMakeContextCurrent(window);
      if (!framebuffers.empty())
        glDeleteFramebuffers(static_cast<GLsizei>(framebuffers.size()), framebuffers.data());
      if (!textures.empty())
        glDeleteTextures(static_cast<GLsizei>(textures.size()), textures.data());
      glfwDestroyWindow(window);
    }
    glfwTerminate();
  }
};

PatternProjector::PatternProjector(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PatternProjector::~PatternProjector() = default;

Result<std::unique_ptr<PatternProjector>> PatternProjector::open(
    const PatternProjectorOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((!x11 || !*x11) && (!wayland || !*wayland))
    return failed_precondition(
        "projector: no display (DISPLAY and WAYLAND_DISPLAY are unset); run on the machine's "
        "desktop session, or under xvfb-run for a test");
  glfwSetErrorCallback(on_glfw_error);
  if (!glfwInit())
    return failed_precondition("projector: cannot open the display: " + take_glfw_error());
  auto impl = std::make_unique<Impl>();  // terminates GLFW on every failure path below

  int count = 0;
  GLFWmonitor** monitors = glfwGetMonitors(&count);
  if (options.fullscreen || options.monitor > 0) {
    if (options.monitor >= count) {
      std::string names;
      for (int i = 0; i < count; ++i)
        names += (i ? ", " : "") + std::to_string(i) + " '" + glfwGetMonitorName(monitors[i]) + "'";
      return not_found("projector: no monitor " + std::to_string(options.monitor) + "; " +
                       (count ? "connected: " + names : std::string("no monitors connected")));
    }
  }
  GLFWmonitor* monitor = count > 0 ? monitors[std::min(options.monitor, count - 1)] : nullptr;
  const GLFWvidmode* mode = monitor ? glfwGetVideoMode(monitor) : nullptr;
  impl->monitor_index = options.monitor;
  impl->monitor_name = monitor ? glfwGetMonitorName(monitor) : "none";
  impl->refresh = mode ? mode->refreshRate : 0;
  impl->fullscreen = options.fullscreen;

  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
  glfwWindowHint(GLFW_DOUBLEBUFFER, GLFW_TRUE);
  glfwWindowHint(GLFW_AUTO_ICONIFY, GLFW_FALSE);  // keep showing when another window has focus
  int w = options.window_width > 0 ? options.window_width : 640;
  int h = options.window_height > 0 ? options.window_height : 400;
  if (options.fullscreen) {
    glfwWindowHint(GLFW_RED_BITS, mode->redBits);
    glfwWindowHint(GLFW_GREEN_BITS, mode->greenBits);
    glfwWindowHint(GLFW_BLUE_BITS, mode->blueBits);
    glfwWindowHint(GLFW_REFRESH_RATE, mode->refreshRate);
    w = mode->width;
    h = mode->height;
  }
  impl->window =
      glfwCreateWindow(w, h, "gvkit patterns", options.fullscreen ? monitor : nullptr, nullptr);
  if (!impl->window)
    return failed_precondition("projector: cannot create an OpenGL window: " + take_glfw_error());
  glfwMakeContextCurrent(impl->window);
  pin_gl_driver_modules();
  glfwSwapInterval(options.vsync ? 1 : 0);
  if (epoxy_gl_version() < 30 && !epoxy_has_gl_extension("GL_ARB_framebuffer_object"))
    return unsupported(
        "projector: OpenGL 3.0 or GL_ARB_framebuffer_object is needed, the "
        "context has " +
        std::to_string(epoxy_gl_version() / 10) + "." + std::to_string(epoxy_gl_version() % 10));
  glfwGetFramebufferSize(impl->window, &impl->width, &impl->height);
  if (options.fullscreen) glfwSetInputMode(impl->window, GLFW_CURSOR, GLFW_CURSOR_HIDDEN);
  return std::unique_ptr<PatternProjector>(new PatternProjector(std::move(impl)));
}

Status PatternProjector::set_patterns(const std::vector<cv::Mat>& patterns) {
  if (patterns.empty()) return invalid_argument("projector: the pattern set is empty");
  std::vector<cv::Mat> rgb;
  for (size_t i = 0; i < patterns.size(); ++i) {
    const cv::Mat& p = patterns[i];
    const std::string name = "projector: pattern " + std::to_string(i);
    if (p.empty()) return invalid_argument(name + " is empty");
    if (p.size() != patterns[0].size())
      return invalid_argument(name + ": size " + std::to_string(p.cols) + "x" +
                              std::to_string(p.rows) + " differs from pattern 0's");
    cv::Mat eight;
    if (p.depth() == CV_16U)
      p.convertTo(eight, CV_8U, 1.0 / 257.0);
    else if (p.depth() == CV_8U)
      eight = p;
    else
      return unsupported(name + ": depth " + std::to_string(p.depth()) + " (use CV_8U/CV_16U)");
    cv::Mat out;
    if (eight.channels() == 1)
      cv::cvtColor(eight, out, cv::COLOR_GRAY2RGB);
    else if (eight.channels() == 3)
      cv::cvtColor(eight, out, cv::COLOR_BGR2RGB);
    else
      return unsupported(name + ": " + std::to_string(p.channels()) + " channels (use 1 or 3)");
    rgb.push_back(out.isContinuous() ? out : out.clone());
  }
  glfwMakeContextCurrent(impl_->window);
  if (!impl_->framebuffers.empty()) {
    glDeleteFramebuffers(static_cast<GLsizei>(impl_->framebuffers.size()),
                         impl_->framebuffers.data());
    glDeleteTextures(static_cast<GLsizei>(impl_->textures.size()), impl_->textures.data());
  }
  const GLsizei n = static_cast<GLsizei>(rgb.size());
  impl_->textures.assign(rgb.size(), 0);
  impl_->framebuffers.assign(rgb.size(), 0);
  glGenTextures(n, impl_->textures.data());
  glGenFramebuffers(n, impl_->framebuffers.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  for (size_t i = 0; i < rgb.size(); ++i) {
    glBindTexture(GL_TEXTURE_2D, impl_->textures[i]);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, rgb[i].cols, rgb[i].rows, 0, GL_RGB, GL_UNSIGNED_BYTE,
                 rgb[i].data);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, impl_->framebuffers[i]);
    glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D,
                           impl_->textures[i], 0);
    if (glCheckFramebufferStatus(GL_READ_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      return unsupported("projector: the OpenGL driver cannot read back an RGB8 texture");
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  impl_->pattern_size = rgb[0].size();
  if (glGetError() != GL_NO_ERROR)
    return io_error("projector: uploading the patterns failed (out of GPU memory?)");
  return Status::ok();
}

int PatternProjector::pattern_count() const { return static_cast<int>(impl_->textures.size()); }

Result<Timestamp> PatternProjector::show(int k) {
  GVKIT_CHECK(k >= 0 && k < pattern_count(), "pattern index out of range");
  glfwPollEvents();
  if (glfwWindowShouldClose(impl_->window))
    return failed_precondition("projector: the pattern window was closed");
  glfwMakeContextCurrent(impl_->window);
  glfwGetFramebufferSize(impl_->window, &impl_->width, &impl_->height);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, impl_->framebuffers[static_cast<size_t>(k)]);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  // Image row 0 is the top; OpenGL's is the bottom: flip while blitting.
  glBlitFramebuffer(0, 0, impl_->pattern_size.width, impl_->pattern_size.height, 0, impl_->height,
                    impl_->width, 0, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glfwSwapBuffers(impl_->window);
  glFinish();
  return monotonic_now();
}

Result<std::vector<PatternPresentation>> PatternProjector::run_cycles(int cycles,
                                                                      int64_t first_cycle) {
  std::vector<PatternPresentation> shown;
  for (int c = 0; c < cycles; ++c)
    for (int k = 0; k < pattern_count(); ++k) {
      GVKIT_ASSIGN_OR_RETURN(Timestamp t, show(k));
      shown.push_back({first_cycle + c, k, t});
    }
  return shown;
}

std::string PatternProjector::describe() const {
  char text[256];
  std::snprintf(text, sizeof(text), "monitor %d '%s' %dx%d @ %.4g Hz, %s", impl_->monitor_index,
                impl_->monitor_name.c_str(), impl_->width, impl_->height, impl_->refresh,
                impl_->fullscreen ? "fullscreen" : "windowed");
  return text;
}

double PatternProjector::refresh_hz() const { return impl_->refresh; }
cv::Size PatternProjector::size() const { return {impl_->width, impl_->height}; }
bool PatternProjector::close_requested() const { return glfwWindowShouldClose(impl_->window) != 0; }

}  // namespace gvkit
