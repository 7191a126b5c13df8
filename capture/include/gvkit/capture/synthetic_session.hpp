#pragma once
// Makes a synthetic session (the project's embedded default source): the ICT face animated by an
// expression track, rendered through the synthetic projector-camera, written as a session
// folder with ground truth (gt/frame_NNNNNN.exr, gt/frame_NNNNNN.landmarks.json).

#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "gvkit/capture/synthetic_renderer.hpp"
#include "gvkit/capture/synthetic_rig.hpp"
#include "gvkit/core/calibration_io.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

struct SyntheticSessionOptions {
  std::filesystem::path ict_dir;  // ../shared/data/ict-facekit
  int frames = 60;
  std::string pattern = "psp3-f16";  // create_pattern_set name
  std::string expressions = "mix";   // ExpressionTrack name
  uint64_t seed = 1;
  bool head_motion = false;
  double fps = 30;
  double face_distance_mm = 650;  // landmark centroid depth
  double gamma_compensation = 0;  // > 0: patterns sent as value^(1/this) (a LUT)
  SyntheticRigOptions rig;
  RenderOptions render;
  bool progress = true;

  // A plain folder instead of a session: a foreign rig's data as gvkit meets it. The images of
  // frame i are img_<i*N+1> .. img_<i*N+N>.<image_format> (numbered from 1, no padding, so only
  // a natural sort orders them), the calibration is calibration.yml in calibration_layout, gt/
  // is written as for a session, and there is no session.json.
  bool plain_folder = false;
  std::string image_format = "png";  // png (8/16 bit) or bmp (8 bit only)
  CalibrationFormat calibration_layout = CalibrationFormat::kProcam;

  Status check() const;
  nlohmann::json to_json() const;
};

// Renders and writes the session (frames in parallel). Fails naming the input or the frame.
Status write_synthetic_session(const std::filesystem::path& dir,
                               const SyntheticSessionOptions& options);

}  // namespace gvkit::capture
