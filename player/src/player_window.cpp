// The GLFW + Dear ImGui player window. Drawing of the mesh is GlMeshPainter's (shared with the
// offscreen renderer); this file is the window, input, layout and panels.
#include "gvkit/player/player_window.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <epoxy/gl.h>
// GLFW after epoxy, and without its own GL header.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <opencv2/imgproc.hpp>

#include "gl_mesh_painter.hpp"
#include "gvkit/core/gl_driver_modules.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/log.hpp"
#include "gvkit/player/colormap.hpp"
#include "gvkit/player/frame_prefetcher.hpp"
#include "gvkit/player/geometry_error.hpp"
#include "gvkit/player/geometry_image_preview.hpp"
#include "gvkit/player/playback_clock.hpp"
#include "gvkit/player/view_camera.hpp"

namespace gvkit::player {
namespace {

constexpr float kPanelWidth = 340.0f;
constexpr float kTimelineHeight = 110.0f;
constexpr const char* kNoDisplayHint =
    "; no window can be opened here. Use `gvkit render INPUT -o OUT.mp4` (or -o OUT_DIR for PNG "
    "frames) to render without a display";

std::string g_glfw_error;  // last GLFW error text (GLFW reports errors through a callback)
double g_scroll = 0;       // wheel steps since the last frame

void on_glfw_error(int code, const char* text) { g_glfw_error = text ? text : "unknown"; }
void on_scroll(GLFWwindow*, double, double dy) { g_scroll += dy; }

// Edge detection of keys polled from GLFW (so ImGui keeps its own callbacks).
class KeyEdges {
 public:
  bool pressed(GLFWwindow* w, int key) {
    const bool down = glfwGetKey(w, key) == GLFW_PRESS;
    const bool was = down_[key];
    down_[key] = down;
    return down && !was;
  }

 private:
  std::map<int, bool> down_;
};

Status write_screenshot(const std::string& path, int fb_w, int fb_h) {
  cv::Mat rgba(fb_h, fb_w, CV_8UC4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, fb_w, fb_h, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  cv::flip(bgr, bgr, 0);
  return write_image(path, bgr);
}

float percentile99(const std::vector<float>& errors) {
  std::vector<float> v;
  for (float e : errors)
    if (e >= 0) v.push_back(e);
  if (v.empty()) return 1.0f;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(0.99 * v.size()));
  std::nth_element(v.begin(), v.begin() + static_cast<ptrdiff_t>(k), v.end());
  return std::max(v[k], 1e-3f);
}

// Everything the loop keeps between pictures.
struct ViewState {
  std::unique_ptr<ViewCamera> camera;
  ShadingMode shading = ShadingMode::kLit;
  float error_max_mm = 0;
  bool have_mesh = false;
  MeshBuffers mesh;           // the mesh on screen (for errors against the reference)
  int64_t shown_index = -1;   // sequence index on screen
  std::string frame_message;  // why the requested frame is not the one shown
  std::optional<GeometryErrorStats> error_stats;
  std::vector<float> errors;
  GLuint image_texture = 0;
  cv::Size image_size;
  double fps_measured = 0;
  int64_t live_frames = 0;
};

void show_mesh(ViewState& s, GlMeshPainter& painter, const GeometryImage& image, MeshBuffers mesh,
               FrameSequence* reference) {
  painter.upload(mesh);
  if (!s.camera) s.camera = std::make_unique<ViewCamera>(scene_frame(mesh));
  // The geometry image beside the 3D view.
  const cv::Mat rgb = geometry_image_preview_rgb(image);
  if (!s.image_texture) glGenTextures(1, &s.image_texture);
  glBindTexture(GL_TEXTURE_2D, s.image_texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, rgb.cols, rgb.rows, 0, GL_RGB, GL_UNSIGNED_BYTE,
               rgb.data);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glBindTexture(GL_TEXTURE_2D, 0);
  s.image_size = rgb.size();
  s.error_stats.reset();
  s.errors.clear();
  if (reference && image.index < reference->frame_count()) {
    auto ref = reference->frame(image.index);
    if (ref.is_ok()) {
      auto errors = vertex_errors_mm(mesh, *ref);
      auto stats = geometry_error(image, *ref);
      if (errors.is_ok() && stats.is_ok()) {
        s.errors = std::move(errors).value();
        s.error_stats = *stats;
        if (s.error_max_mm <= 0) s.error_max_mm = percentile99(s.errors);
        painter.upload_errors(s.errors);
      } else {
        s.frame_message =
            "reference: " + (errors.is_ok() ? stats.status() : errors.status()).message();
      }
    } else {
      s.frame_message = "reference: " + ref.status().message();
    }
  }
  s.mesh = std::move(mesh);
  s.have_mesh = true;
}

void draw_colour_bar_overlay(float max_mm) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 p = ImGui::GetCursorScreenPos();
  const float w = 200, h = 12;
  const int steps = 32;
  for (int i = 0; i < steps; ++i) {
    const cv::Vec3f a = turbo_rgb(static_cast<float>(i) / steps);
    const cv::Vec3f b = turbo_rgb(static_cast<float>(i + 1) / steps);
    const ImU32 ca = IM_COL32(255 * a[0], 255 * a[1], 255 * a[2], 255);
    const ImU32 cb = IM_COL32(255 * b[0], 255 * b[1], 255 * b[2], 255);
    dl->AddRectFilledMultiColor(ImVec2(p.x + w * i / steps, p.y),
                                ImVec2(p.x + w * (i + 1) / steps, p.y + h), ca, cb, cb, ca);
  }
  ImGui::Dummy(ImVec2(w, h));
  ImGui::Text("0 mm %*s %.3g mm", 18, "", max_mm);
}

}  // namespace

Status PlayerWindowOptions::check() const {
  if (!sequence && !live)
    return invalid_argument("player: nothing to play (no sequence, no live queue)");
  if (width < 320 || height < 240)
    return invalid_argument("player: window must be at least 320x240");
  if (!(speed > 0)) return invalid_argument("player: speed must be > 0");
  if (exit_after_frames < 0) return invalid_argument("player: exit-after-frames must be >= 0");
  return mesh.check();
}

Status run_player_window(const PlayerWindowOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((!display || !*display) && (!wayland || !*wayland))
    return unsupported(std::string("no display (DISPLAY and WAYLAND_DISPLAY are unset)") +
                       kNoDisplayHint);
  glfwSetErrorCallback(on_glfw_error);
  if (!glfwInit()) return unsupported("cannot initialise GLFW: " + g_glfw_error + kNoDisplayHint);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 0);  // multisampling costs 2-3x on llvmpipe (docs/benchmarks.md)
  const std::string title = options.title + (options.sequence ? " - " + options.sequence->name()
                                                              : std::string(" - live"));
  GLFWwindow* window =
      glfwCreateWindow(options.width, options.height, title.c_str(), nullptr, nullptr);
  if (!window) {
    glfwTerminate();
    return unsupported("cannot open an OpenGL 3.3 window: " + g_glfw_error + kNoDisplayHint);
  }
  glfwMakeContextCurrent(window);
  pin_gl_driver_modules();
  glfwSwapInterval(options.exit_after_frames > 0 ? 0 : 1);
  glfwSetScrollCallback(window, on_scroll);  // before ImGui, which chains to it

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui::StyleColorsLight();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330");

  Status result;
  {
    auto painter_result = GlMeshPainter::create();
    if (!painter_result.is_ok()) {
      result = painter_result.status();
    } else {
      std::unique_ptr<GlMeshPainter> painter = std::move(painter_result).value();
      logger().info("play: {} ({})", title, gl_description());
      FrameSequence* seq = options.sequence.get();
      // Deterministic runs: the clock advances one frame per picture.
      int64_t pictures = 0;
      const double fps = seq ? seq->fps() : 30.0;
      PlaybackClock::NowFn now = monotonic_now;
      if (options.exit_after_frames > 0)
        now = [&pictures, fps] { return Timestamp(static_cast<int64_t>(pictures * 1e9 / fps)); };
      std::optional<PlaybackClock> clock;
      std::unique_ptr<FramePrefetcher> prefetcher;
      std::vector<float> kbits;
      double mean_kbps = 0;
      if (seq) {
        clock.emplace(seq->frame_count(), fps, now);
        clock->set_loop(options.loop);
        (void)clock->set_speed(options.speed);
        if (options.start_playing) clock->play();
        PrefetchOptions prefetch;
        prefetch.loop = options.loop;
        prefetch.mesh = options.mesh;
        prefetcher = std::make_unique<FramePrefetcher>(options.sequence, prefetch);
        for (int64_t i = 0; i < seq->frame_count(); ++i) {
          const auto bits = seq->frame_bits(i);
          kbits.push_back(bits ? static_cast<float>(*bits) / 1000.0f : 0.0f);
          mean_kbps += kbits.back() * fps / static_cast<double>(seq->frame_count());
        }
      }
      ViewState s;
      s.shading = options.shading;
      KeyEdges keys;
      double last_x = 0, last_y = 0;
      auto last_time = std::chrono::steady_clock::now();
      bool screenshot_requested = false;
      std::string screenshot_note;

      while (!glfwWindowShouldClose(window)) {
        glfwPollEvents();
        ImGuiIO& io = ImGui::GetIO();
        // Keys and mouse (when ImGui does not want them).
        if (!io.WantCaptureKeyboard) {
          if (keys.pressed(window, GLFW_KEY_ESCAPE) || keys.pressed(window, GLFW_KEY_Q))
            glfwSetWindowShouldClose(window, GLFW_TRUE);
          if (clock) {
            if (keys.pressed(window, GLFW_KEY_SPACE)) clock->toggle();
            if (keys.pressed(window, GLFW_KEY_RIGHT)) clock->step(1);
            if (keys.pressed(window, GLFW_KEY_LEFT)) clock->step(-1);
            if (keys.pressed(window, GLFW_KEY_HOME)) clock->seek(0);
            if (keys.pressed(window, GLFW_KEY_END)) clock->seek(clock->frame_count() - 1);
            if (keys.pressed(window, GLFW_KEY_L)) {
              clock->set_loop(!clock->loop());
              prefetcher->set_loop(clock->loop());
            }
          }
          if (keys.pressed(window, GLFW_KEY_R) && s.camera) s.camera->reset();
          if (keys.pressed(window, GLFW_KEY_S)) screenshot_requested = true;
          const ShadingMode by_key[] = {ShadingMode::kLit, ShadingMode::kTexture,
                                        ShadingMode::kNormals, ShadingMode::kWireframe,
                                        ShadingMode::kError};
          for (int k = 0; k < 5; ++k)
            if (keys.pressed(window, GLFW_KEY_1 + k) && (k < 4 || options.reference))
              s.shading = by_key[k];
        }
        double mx = 0, my = 0;
        glfwGetCursorPos(window, &mx, &my);
        if (!io.WantCaptureMouse && s.camera) {
          const double dx = mx - last_x, dy = my - last_y;
          if (glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS)
            s.camera->orbit(dx * 0.008, dy * 0.008);
          if (glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
              glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS)
            s.camera->pan(-dx * 0.003, dy * 0.003);
          if (g_scroll != 0) s.camera->zoom(std::pow(0.9, g_scroll));
        }
        g_scroll = 0;
        last_x = mx, last_y = my;

        // The frame to show.
        if (seq) {
          const int64_t want = clock->current_frame();
          if (want != s.shown_index) {
            auto frame = (!s.have_mesh || options.exit_after_frames > 0)
                             ? prefetcher->get(want)
                             : prefetcher->try_get(want);
            if (frame) {
              s.shown_index = want;
              s.frame_message.clear();
              if (frame->status.is_ok())
                show_mesh(s, *painter, frame->image, frame->mesh, options.reference.get());
              else
                s.frame_message = frame->status.message();
            }
          }
        } else if (auto image = options.live->take_latest()) {
          ++s.live_frames;
          s.shown_index = image->index;
          s.frame_message.clear();
          MeshBuffers mesh = mesh_buffers_from_geometry_image(*image, options.mesh);
          show_mesh(s, *painter, *image, std::move(mesh), nullptr);
        }

        // Layout (ImGui units = window coordinates; GL viewport in framebuffer pixels).
        int win_w = 0, win_h = 0, fb_w = 0, fb_h = 0;
        glfwGetWindowSize(window, &win_w, &win_h);
        glfwGetFramebufferSize(window, &fb_w, &fb_h);
        const float sx = win_w > 0 ? static_cast<float>(fb_w) / win_w : 1.0f;
        const float sy = win_h > 0 ? static_cast<float>(fb_h) / win_h : 1.0f;
        const float timeline_h = seq ? kTimelineHeight : 0.0f;
        const float view_w = std::max(1.0f, win_w - kPanelWidth),
                    view_h = std::max(1.0f, win_h - timeline_h);

        glViewport(0, 0, fb_w, fb_h);
        glDisable(GL_SCISSOR_TEST);
        glClearColor(0.88f, 0.89f, 0.91f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        const GLint vx = 0, vy = static_cast<GLint>(timeline_h * sy);
        const GLsizei vw = static_cast<GLsizei>(view_w * sx),
                      vh = static_cast<GLsizei>(view_h * sy);
        glViewport(vx, vy, vw, vh);
        glEnable(GL_SCISSOR_TEST);
        glScissor(vx, vy, vw, vh);
        glClearColor(kBackgroundRgb[0], kBackgroundRgb[1], kBackgroundRgb[2], 1.0f);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        if (s.have_mesh && s.camera) {
          DrawStyle style;
          style.mode = (s.shading == ShadingMode::kError && s.errors.empty()) ? ShadingMode::kLit
                                                                              : s.shading;
          style.error_max_mm = s.error_max_mm > 0 ? s.error_max_mm : 1.0f;
          painter->draw(s.camera->view_from_world(), s.camera->clip_from_view(view_w / view_h),
                        style);
        }
        glDisable(GL_SCISSOR_TEST);
        glViewport(0, 0, fb_w, fb_h);

        // Panels.
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        const auto t = std::chrono::steady_clock::now();
        const double dt = std::chrono::duration<double>(t - last_time).count();
        last_time = t;
        if (dt > 0)
          s.fps_measured = s.fps_measured > 0 ? 0.9 * s.fps_measured + 0.1 / dt : 1.0 / dt;

        // Overlay: fps, frame, bitrate, error.
        ImGui::SetNextWindowPos(ImVec2(8, 8));
        ImGui::SetNextWindowBgAlpha(0.6f);
        ImGui::Begin("overlay", nullptr,
                     ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                         ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoFocusOnAppearing |
                         ImGuiWindowFlags_NoNav);
        ImGui::Text("%.1f fps", s.fps_measured);
        if (seq) {
          ImGui::Text("frame %lld / %lld   %.2f s", static_cast<long long>(s.shown_index),
                      static_cast<long long>(seq->frame_count() - 1),
                      s.shown_index >= 0 ? s.shown_index / fps : 0.0);
          if (s.shown_index >= 0 && s.shown_index < static_cast<int64_t>(kbits.size()))
            ImGui::Text("%.1f kbit/frame  %.0f kbit/s (mean %.0f kbit/s)", kbits[s.shown_index],
                        kbits[s.shown_index] * fps, mean_kbps);
        } else {
          ImGui::Text("live: %lld frames shown, %lld dropped",
                      static_cast<long long>(s.live_frames),
                      static_cast<long long>(options.live->dropped()));
          if (options.live_status) ImGui::TextUnformatted(options.live_status().c_str());
        }
        if (s.error_stats)
          ImGui::Text("RMS %.4f mm  max %.3f mm  PSNR %.2f dB", s.error_stats->rms_mm,
                      s.error_stats->max_mm, s.error_stats->psnr_db);
        if (s.shading == ShadingMode::kError && !s.errors.empty())
          draw_colour_bar_overlay(s.error_max_mm);
        if (!s.frame_message.empty())
          ImGui::TextColored(ImVec4(0.8f, 0.1f, 0.1f, 1), "%s", s.frame_message.c_str());
        if (!screenshot_note.empty()) ImGui::TextUnformatted(screenshot_note.c_str());
        ImGui::End();

        // Side panel.
        ImGui::SetNextWindowPos(ImVec2(view_w, 0));
        ImGui::SetNextWindowSize(ImVec2(kPanelWidth, static_cast<float>(win_h)));
        ImGui::Begin(
            "gvkit", nullptr,
            ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
        ImGui::TextWrapped("%s", seq ? seq->name().c_str() : "live preview");
        if (clock) {
          if (ImGui::Button(clock->playing() ? "Pause" : "Play")) clock->toggle();
          ImGui::SameLine();
          if (ImGui::Button("<")) clock->step(-1);
          ImGui::SameLine();
          if (ImGui::Button(">")) clock->step(1);
          ImGui::SameLine();
          bool loop = clock->loop();
          if (ImGui::Checkbox("loop", &loop)) {
            clock->set_loop(loop);
            prefetcher->set_loop(loop);
          }
          float speed = static_cast<float>(clock->speed());
          if (ImGui::SliderFloat("speed", &speed, 0.1f, 4.0f, "%.2fx"))
            (void)clock->set_speed(speed);
        }
        const char* names[] = {"lit", "texture", "normals", "wireframe", "error"};
        int mode = static_cast<int>(s.shading);
        if (ImGui::Combo("shading", &mode, names, options.reference ? 5 : 4))
          s.shading = static_cast<ShadingMode>(mode);
        if (options.reference)
          ImGui::SliderFloat("error max (mm)", &s.error_max_mm, 0.001f, 10.0f, "%.3f",
                             ImGuiSliderFlags_Logarithmic);
        if (ImGui::Button("Reset view (R)") && s.camera) s.camera->reset();
        ImGui::SameLine();
        if (ImGui::Button("Screenshot (S)")) screenshot_requested = true;
        ImGui::Separator();
        if (s.image_texture && s.image_size.width > 0) {
          ImGui::Text("geometry image %dx%d (xyz as RGB)", s.image_size.width, s.image_size.height);
          const float w = kPanelWidth - 20;
          ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(s.image_texture)),
                       ImVec2(w, w * s.image_size.height / s.image_size.width));
          ImGui::Text("%zu vertices, %zu triangles", s.mesh.vertex_count(),
                      s.mesh.triangle_count());
        }
        ImGui::Separator();
        ImGui::TextWrapped(
            "Drag: orbit (left), pan (right). Wheel: zoom. Space: play/pause, "
            "arrows: step, 1-5: shading, L: loop, Q: quit.");
        ImGui::End();

        // Timeline with the per-frame bits.
        if (seq) {
          ImGui::SetNextWindowPos(ImVec2(0, view_h));
          ImGui::SetNextWindowSize(ImVec2(view_w, timeline_h));
          ImGui::Begin("timeline", nullptr,
                       ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove);
          const float max_kbits =
              kbits.empty() ? 1.0f : *std::max_element(kbits.begin(), kbits.end());
          ImGui::PlotHistogram("##bits", kbits.data(), static_cast<int>(kbits.size()), 0,
                               "kbit per frame", 0.0f, max_kbits * 1.05f,
                               ImVec2(view_w - 16, timeline_h - 46));
          int frame = static_cast<int>(std::max<int64_t>(s.shown_index, 0));
          ImGui::SetNextItemWidth(view_w - 16);
          if (ImGui::SliderInt("##frame", &frame, 0, static_cast<int>(seq->frame_count() - 1)))
            clock->seek(frame);
          ImGui::End();
        }

        ImGui::Render();
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        ++pictures;
        const bool last = options.exit_after_frames > 0 && pictures >= options.exit_after_frames;
        if (screenshot_requested || (last && !options.screenshot_path.empty())) {
          Status shot = write_screenshot(options.screenshot_path, fb_w, fb_h);
          screenshot_note = shot.is_ok() ? "saved " + options.screenshot_path : shot.message();
          if (!shot.is_ok()) logger().warn("{}", shot.message());
          if (last && !shot.is_ok()) result = shot;
          screenshot_requested = false;
        }
        glfwSwapBuffers(window);
        if (last) break;
        if (!seq && options.close_when_live_ends && options.live->closed() &&
            options.live->pending() == 0)
          break;
      }
      if (s.image_texture) glDeleteTextures(1, &s.image_texture);
      prefetcher.reset();
      painter.reset();
    }
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  glfwTerminate();
  return result;
}

}  // namespace gvkit::player
