#pragma once
// Synthetic calibration captures: a checkerboard (with a white margin) in several poses in front
// of the synthetic projector-camera, each rendered under calibration_patterns(). Ground truth for
// testing calibrate_projector_camera().

#include <cstdint>
#include <filesystem>
#include <vector>

#include "gvkit/capture/projector_calibration.hpp"
#include "gvkit/capture/synthetic_renderer.hpp"
#include "gvkit/core/fringe_set.hpp"

namespace gvkit::capture {

// The board as a mesh in board coordinates (corner (0,0) at the origin, z = 0): dark and light
// squares (albedo 0.2 / 0.85) and a light margin one square wide.
SyntheticScene checkerboard_scene(const CalibrationBoard& board);

// Renders `poses` (<= 12) board poses (tilted up to ~25 degrees, ~600-700 mm away), one FringeSet
// per pose (index = pose). Fails when the pattern set does not parse.
Result<std::vector<FringeSet>> render_calibration_captures(
    const Calibration& truth, const CalibrationBoard& board,
    const ProjectorCalibrationOptions& options, const RenderOptions& render, int poses,
    uint64_t seed);

// Writes the captures as a session folder (session_info.hpp) with source.kind "calibration":
// each frame is one pose with 1 + 2 N images; the true calibration is calibration.yaml.
Status write_board_session(const std::filesystem::path& dir, const Calibration& truth,
                           const CalibrationBoard& board,
                           const ProjectorCalibrationOptions& options, const RenderOptions& render,
                           int poses, uint64_t seed);

}  // namespace gvkit::capture
