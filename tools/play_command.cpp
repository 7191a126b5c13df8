// gvkit play INPUT [--reference OTHER]: the interactive 3D player window (GLFW + Dear ImGui).
#include <memory>
#include <string>

#include "command.hpp"
#include "gvkit/player/frame_sequence.hpp"
#include "gvkit/player/player_window.hpp"
#include "tool_support.hpp"

namespace gvkit::tools {
namespace {
using namespace gvkit::player;

struct PlayCommandOptions {
  std::string input, reference, shading = "lit", size = "1280x800", screenshot;
  double speed = 1.0;
  bool no_loop = false, paused = false;
  int64_t exit_after_frames = 0;
  int mesh_stride = 1;
};

void run_play(const PlayCommandOptions& o) {
  PlayerWindowOptions w;
  w.shading = value_or_throw(parse_shading_mode(o.shading));
  std::tie(w.width, w.height) = value_or_throw(parse_size(o.size));
  w.speed = o.speed;
  w.loop = !o.no_loop;
  w.start_playing = !o.paused;
  w.exit_after_frames = o.exit_after_frames;
  w.mesh.stride = o.mesh_stride;
  if (!o.screenshot.empty()) w.screenshot_path = o.screenshot;
  w.sequence = value_or_throw(FrameSequence::create(o.input));
  if (!o.reference.empty()) w.reference = value_or_throw(FrameSequence::create(o.reference));
  if (w.shading == ShadingMode::kError && !w.reference)
    throw CommandFailed(invalid_argument("--shading error needs --reference"));
  throw_if_error(w.check());
  throw_if_error(run_player_window(w));
}

}  // namespace

void add_play_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("play", "Play a geometry video in a 3D window");
  auto o = std::make_shared<PlayCommandOptions>();
  cmd->add_option("input", o->input, "Geometry video: FILE.gvid or a folder of frame_NNNNNN.exr")
      ->required();
  cmd->add_option("--reference", o->reference,
                  "Reference video on the same domain: error shading, RMS and PSNR");
  cmd->add_option("--shading", o->shading, "lit, texture, normals, wireframe or error")
      ->capture_default_str();
  cmd->add_option("--size", o->size, "Window size WxH")->capture_default_str();
  cmd->add_option("--speed", o->speed, "Playback speed (1 = real time)")->capture_default_str();
  cmd->add_option("--mesh-stride", o->mesh_stride,
                  "Use every Nth pixel (2 = 4x fewer triangles, faster on software OpenGL)")
      ->capture_default_str();
  cmd->add_flag("--no-loop", o->no_loop, "Stop at the last frame");
  cmd->add_flag("--paused", o->paused, "Start paused");
  cmd->add_option("--screenshot", o->screenshot,
                  "Screenshot file (S key; also written at the end with --exit-after-frames)");
  cmd->add_option("--exit-after-frames", o->exit_after_frames,
                  "Advance one frame per picture and close after N pictures (tests, timing)");
  cmd->callback([o] { run_play(*o); });
}

}  // namespace gvkit::tools
