#pragma once
// The description of a recorded session folder (session.json; docs/session-format.md):
//   session.json            this, rewritten atomically after every frame
//   calibration.yaml        the rig's Calibration (gvkit format)
//   frames/frame_NNNNNN_kK.png   image K of frame N, lossless 8- or 16-bit grey
//   gt/frame_NNNNNN.exr     synthetic sessions: ground truth (ground_truth.hpp)
//   gt/frame_NNNNNN.landmarks.json  synthetic sessions: the 68 true landmarks

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gvkit/core/status.hpp"
#include "gvkit/core/timestamp.hpp"

namespace gvkit::capture {

struct SessionFrame {
  int64_t index = 0;
  Timestamp timestamp{0};
  std::vector<std::string> images;  // paths relative to the session folder
};

struct SessionInfo {
  static constexpr const char* kFormat = "gvkit-session";
  static constexpr int kVersion = 1;

  std::string calibration_file = "calibration.yaml";
  std::string pattern;  // pattern set name (create_pattern_set)
  int images_per_frame = 0;
  double fps = 30;
  int width = 0, height = 0;  // camera image size (px)
  int bit_depth = 8;          // significant bits; 10/12-bit data is stored scaled to 16 bits
  int64_t dropped_frames = 0;
  std::string ground_truth_dir;  // "gt" for synthetic sessions, else empty
  // Expected depth of the face (mm), which resolves the whole-period ambiguity of spatially
  // unwrapped pattern sets (ReconstructOptions::depth_prior_mm); 0 when not recorded.
  double depth_prior_mm = 0;
  nlohmann::json source = nlohmann::json::object();  // how it was made (synthetic options, device)
  std::vector<SessionFrame> frames;

  nlohmann::json to_json() const;
  // Fails with `where` in the message on a wrong format name, an unknown major version or a
  // missing or mistyped field.
  static Result<SessionInfo> from_json(const nlohmann::json& json, const std::string& where);
};

}  // namespace gvkit::capture
