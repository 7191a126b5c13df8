// gvkit calibrate SESSION -o calibration.yaml: projector-camera calibration from checkerboard
// captures under fringe patterns (each frame: white, vertical fringes, horizontal fringes).
// gvkit calibrate --synth-board DIR writes such a session from the synthetic rig.
#include <cstdio>
#include <memory>
#include <regex>
#include <string>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gvkit/capture/projector_calibration.hpp"
#include "gvkit/capture/session_reader.hpp"
#include "gvkit/capture/synthetic_board.hpp"
#include "gvkit/capture/synthetic_rig.hpp"
#include "gvkit/core/calibration_io.hpp"
#include "gvkit/core/json_io.hpp"

namespace gvkit::tools {
namespace {

cv::Size parse_size(const std::string& text, const std::string& flag) {
  std::smatch m;
  if (!std::regex_match(text, m, std::regex(R"((\d+)x(\d+))")))
    throw CommandFailed(invalid_argument(flag + " must be WxH, not '" + text + "'"));
  return {std::stoi(m[1]), std::stoi(m[2])};
}

struct CalibrateArgs {
  std::string input, output, board = "8x6", projector = "912x570", synth_board, size = "512x512";
  double square_mm = 25;
  int poses = 8;
  capture::ProjectorCalibrationOptions options;
};

void run(const CalibrateArgs& a) {
  capture::CalibrationBoard board;
  const cv::Size corners = parse_size(a.board, "--board");
  board.inner_corners_x = corners.width;
  board.inner_corners_y = corners.height;
  board.square_mm = a.square_mm;
  throw_if_error(board.check());
  capture::ProjectorCalibrationOptions options = a.options;
  const cv::Size projector = parse_size(a.projector, "--projector");
  options.projector_width = projector.width;
  options.projector_height = projector.height;
  if (!a.synth_board.empty()) {
    if (a.poses < 1 || a.poses > 12)
      throw CommandFailed(
          invalid_argument("--poses must be in 1..12, got " + std::to_string(a.poses)));
    capture::SyntheticRigOptions rig;
    const cv::Size size = parse_size(a.size, "--size");
    rig.camera_width = size.width;
    rig.camera_height = size.height;
    rig.projector_width = projector.width;
    rig.projector_height = projector.height;
    throw_if_error(rig.check());
    capture::RenderOptions render;
    render.bit_depth = 12;
    throw_if_error(capture::write_board_session(a.synth_board, capture::synthetic_calibration(rig),
                                                board, options, render, a.poses, 1));
    std::printf("wrote %d synthetic board captures to %s\n", a.poses, a.synth_board.c_str());
    if (a.input.empty()) return;
  }
  if (a.input.empty() || a.output.empty())
    throw CommandFailed(invalid_argument("calibrate needs an input session and -o FILE"));
  const capture::SessionReader session = value_or_throw(capture::SessionReader::open(a.input));
  std::vector<FringeSet> captures;
  for (size_t i = 0; i < session.frame_count(); ++i)
    captures.push_back(value_or_throw(session.read_frame(i)));
  const capture::ProjectorCalibrationResult result =
      value_or_throw(capture::calibrate_projector_camera(captures, board, options));
  throw_if_error(write_calibration(a.output, result.calibration));
  const Calibration& c = result.calibration;
  for (const auto& s : result.skipped) std::printf("skipped %s\n", s.c_str());
  std::printf(
      "calibrated from %d captures: camera f %.2f px, projector f %.2f px, baseline %.2f "
      "mm; reprojection error camera %.3f px, projector %.3f px, stereo %.3f px\n",
      result.poses_used, c.camera_K(0, 0), c.projector_K(0, 0), c.baseline_mm(), c.camera_error_px,
      c.projector_error_px, c.stereo_error_px);
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "calibrate", "Projector-camera calibration from checkerboard captures under fringes");
  auto a = std::make_shared<CalibrateArgs>();
  cmd->add_option("input", a->input,
                  "Session: per frame one white image, then the pattern set with vertical and "
                  "with horizontal fringes");
  cmd->add_option("-o,--output", a->output, "Calibration file to write (.yaml/.json/.xml)");
  cmd->add_option("--board", a->board, "Inner corners WxH")->capture_default_str();
  cmd->add_option("--square", a->square_mm, "Square size (mm)")->capture_default_str();
  cmd->add_option("--pattern", a->options.pattern, "Absolute pattern set of the captures")
      ->capture_default_str();
  cmd->add_option("--projector", a->projector, "Projector size WxH")->capture_default_str();
  cmd->add_option("--synth-board", a->synth_board,
                  "First write synthetic board captures of the default rig to this folder");
  cmd->add_option("--poses", a->poses, "Poses for --synth-board (<= 12)")->capture_default_str();
  cmd->add_option("--size", a->size, "Camera size for --synth-board")->capture_default_str();
  cmd->callback([a] { run(*a); });
}

}  // namespace gvkit::tools
