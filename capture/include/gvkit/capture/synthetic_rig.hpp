#pragma once
// The default synthetic projector-camera rig (DESIGN.md section 7): a 512x512 camera with ~30
// degrees horizontal field of view, and a 912x570 projector 200 mm to the camera's right, toed in
// so the optical axes cross 650 mm ahead (a ~17 degree triangulation angle).

#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "gvkit/core/calibration.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

struct SyntheticRigOptions {
  int camera_width = 512, camera_height = 512;  // px
  double camera_hfov_deg = 30;
  int projector_width = 912, projector_height = 570;  // px
  double projector_focal_px = 1300;                   // ~38 x 25 degrees field of view
  double baseline_mm = 200;                           // projector centre at +x (camera's right)
  double axes_cross_mm = 650;       // the projector's axis meets the camera's at this depth
  std::vector<double> camera_dist;  // OpenCV lens model; empty = ideal pinhole
  std::vector<double> projector_dist;

  Status check() const;
  nlohmann::json to_json() const;  // the rig's geometry, as recorded in session.json
};

// The rig's Calibration (fringe_pitch_px left 0: set it from the pattern set).
Calibration synthetic_calibration(const SyntheticRigOptions& options = {});

}  // namespace gvkit::capture
