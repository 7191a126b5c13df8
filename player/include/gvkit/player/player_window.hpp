#pragma once
// The interactive player: a GLFW window with the 3D view (orbit camera, shading modes), a side
// panel (playback, shading, the geometry image itself), a timeline of per-frame bits and an
// overlay with fps, frame, bitrate and, with a reference, RMS error and PSNR.
// Only built with GVKIT_WITH_PLAYER.
//
// Mouse: left drag orbits, right or middle drag pans, wheel zooms. Keys: space play/pause,
// left/right step, Home/End first/last frame, R reset view, S screenshot, 1-5 shading
// (lit, texture, normals, wireframe, error), L loop, Esc/Q quit.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "gvkit/core/status.hpp"
#include "gvkit/player/frame_sequence.hpp"
#include "gvkit/player/geometry_image_mesh.hpp"
#include "gvkit/player/live_frame_queue.hpp"
#include "gvkit/player/shading_mode.hpp"

namespace gvkit::player {

struct PlayerWindowOptions {
  // What to show: a sequence, or frames pushed live into `live` (then sequence may be null).
  std::shared_ptr<FrameSequence> sequence;
  std::shared_ptr<LiveFrameQueue> live;
  // Live only: a line shown under the frame counts (e.g. the capture pipeline's status with its
  // drop counts), asked for every picture; and whether the window closes by itself once `live`
  // is closed and its last frame was shown.
  std::function<std::string()> live_status;
  bool close_when_live_ends = false;
  // Optional reference on the same domain: error shading, RMS and PSNR per frame.
  std::shared_ptr<FrameSequence> reference;
  int width = 1280, height = 800;  // window size (screen coordinates)
  ShadingMode shading = ShadingMode::kLit;
  GeometryImageMeshOptions mesh;  // e.g. stride 2 for fast playback on software OpenGL
  double speed = 1.0;
  bool loop = true;
  bool start_playing = true;
  // > 0: advance exactly one frame per drawn picture (not by wall time) and close after this
  // many pictures — deterministic runs for tests and timing.
  int64_t exit_after_frames = 0;
  // Screenshot file (PNG) written by the S key and, when exit_after_frames > 0, at the end.
  std::string screenshot_path = "gvkit_screenshot.png";
  std::string title = "gvkit play";
  Status check() const;
};

// Opens the window and runs until it is closed. Fails (kUnsupported) with a message pointing at
// `gvkit render` when there is no display or no OpenGL 3.3 context, and on a failed screenshot.
Status run_player_window(const PlayerWindowOptions& options);

}  // namespace gvkit::player
