#pragma once
// Calibration of a projector-camera pair from checkerboard captures under fringe patterns: the
// camera by cv::calibrateCamera on the board corners; the projector as an inverse camera, from
// the projector pixel (u, v) decoded at each corner (vertical fringes give u, the same pattern
// set turned 90 degrees gives v); then cv::stereoCalibrate for the pose between them.
//
// A capture (one board pose) holds, in order: one image under a white projector, the images of
// the pattern set with vertical fringes, then the same with horizontal fringes
// (calibration_patterns()).

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/core/calibration.hpp"
#include "gvkit/core/fringe_set.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

struct CalibrationBoard {
  int inner_corners_x = 8, inner_corners_y = 6;  // inner corners per row, per column
  double square_mm = 25;
  Status check() const;
  // Corner positions on the board plane (z = 0), row by row, in mm.
  std::vector<cv::Point3f> object_points() const;
};

struct ProjectorCalibrationOptions {
  std::string pattern = "mf4-f16-f1";  // absolute pattern set (no spatial unwrapping)
  int projector_width = 912, projector_height = 570;
  int fit_window_px = 7;  // half size of the window of the local plane fit of u, v at a corner
  Status check() const;
};

// The projector images of one capture: white, vertical fringes, horizontal fringes (CV_32F).
Result<std::vector<cv::Mat>> calibration_patterns(const ProjectorCalibrationOptions& options);

struct ProjectorCalibrationResult {
  Calibration calibration;  // camera size from the captures; fringe_pitch_px from the pattern
  int poses_used = 0;
  std::vector<std::string> skipped;  // "capture N: why"
};

// Fails naming the capture when images are missing or of different sizes, and when fewer than 3
// captures show the whole board.
Result<ProjectorCalibrationResult> calibrate_projector_camera(
    const std::vector<FringeSet>& captures, const CalibrationBoard& board,
    const ProjectorCalibrationOptions& options);

}  // namespace gvkit::capture
