#pragma once
// Test fixture: a user's own rig as gvkit meets it. A smooth head-sized bump (150 mm high, on a
// wall 800 mm away) rendered through the synthetic projector-camera with any pattern list, and
// written as a plain folder of numbered images (img_1.bmp, img_2.bmp, ... img_10.bmp: natural
// order matters) beside a calibration file in a foreign layout. Ground truth comes from the
// renderer. Small images keep every test at a few hundred milliseconds.

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "gvkit/capture/ground_truth.hpp"
#include "gvkit/capture/synthetic_renderer.hpp"
#include "gvkit/capture/synthetic_rig.hpp"
#include "gvkit/core/range_scan.hpp"

namespace gvkit::capture::fixture {

// Height field z(x, y) (mm, camera frame): a wall at 800 mm with a Gaussian bump (the "face")
// whose top, 650 mm away, sits at x = centre_x_mm.
inline double bump_depth_mm(double x, double y, double centre_x_mm = 0, double depth_mm = 650) {
  const double dx = (x - centre_x_mm) / 85.0, dy = y / 105.0;
  return 800.0 - (800.0 - depth_mm) * std::exp(-(dx * dx + dy * dy));
}

// The bump as a triangle grid over [-half, half]^2 mm (x, y at the wall), with a mild albedo
// pattern (0.45 .. 0.85) so decoding sees varying reflectance.
inline SyntheticScene bump_scene(double centre_x_mm = 0, double depth_mm = 650, int grid = 121,
                                 double half_mm = 320) {
  SyntheticScene s;
  for (int j = 0; j < grid; ++j)
    for (int i = 0; i < grid; ++i) {
      const double x = -half_mm + 2 * half_mm * i / (grid - 1);
      const double y = -half_mm + 2 * half_mm * j / (grid - 1);
      const double z = bump_depth_mm(x, y, centre_x_mm, depth_mm);
      // Points on the viewing ray through (x, y) at the wall keep the grid on screen.
      s.positions_mm.emplace_back(x * z / 800.0, y * z / 800.0, z);
      s.albedo.push_back(static_cast<float>(0.65 + 0.2 * std::sin(x / 37.0) * std::cos(y / 53.0)));
    }
  for (int j = 0; j + 1 < grid; ++j)
    for (int i = 0; i + 1 < grid; ++i) {
      const int a = j * grid + i, b = a + 1, c = a + grid, d = c + 1;
      s.triangles.emplace_back(a, c, b);
      s.triangles.emplace_back(b, c, d);
    }
  s.triangle_source.assign(s.triangles.size(), 0);
  return s;
}

// A rig with the given camera and projector sizes (the default geometry otherwise).
inline Calibration rig(cv::Size camera, cv::Size projector = {912, 570}, double hfov_deg = 30) {
  SyntheticRigOptions o;
  o.camera_width = camera.width;
  o.camera_height = camera.height;
  o.camera_hfov_deg = hfov_deg;
  o.projector_width = projector.width;
  o.projector_height = projector.height;
  o.projector_focal_px = 1300.0 * projector.width / 912.0;
  return synthetic_calibration(o);
}

// Writes images as <prefix><first + k>.<ext> (no zero padding) and returns the paths.
inline std::vector<std::filesystem::path> write_numbered(const std::filesystem::path& dir,
                                                         const std::vector<cv::Mat>& images,
                                                         const std::string& prefix,
                                                         const std::string& ext, int first = 1) {
  std::filesystem::create_directories(dir);
  std::vector<std::filesystem::path> out;
  for (size_t k = 0; k < images.size(); ++k) {
    out.push_back(dir / (prefix + std::to_string(first + static_cast<int>(k)) + "." + ext));
    cv::imwrite(out.back().string(), images[k]);
  }
  return out;
}

struct DepthError {
  double rms_mm = 0, max_mm = 0;
  double valid_share = 0;  // of the lit interior pixels, the share the scan measured
  int compared = 0;
};

// Depth error of a scan against the renderer's truth over lit pixels whose 8 neighbours are lit
// (no shadow edge, where one pixel mixes two surfaces).
inline DepthError depth_error(const RangeScan& scan, const SyntheticTruth& truth) {
  DepthError e;
  int interior = 0;
  double sum2 = 0;
  for (int y = 1; y + 1 < truth.lit.rows; ++y)
    for (int x = 1; x + 1 < truth.lit.cols; ++x) {
      bool all_lit = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) all_lit = all_lit && truth.lit.at<uint8_t>(y + dy, x + dx);
      if (!all_lit) continue;
      ++interior;
      if (!scan.valid.at<uint8_t>(y, x)) continue;
      const double d = scan.xyz_mm.at<cv::Vec3f>(y, x)[2] -
                       static_cast<double>(truth.xyz_mm.at<cv::Vec3f>(y, x)[2]);
      sum2 += d * d;
      e.max_mm = std::max(e.max_mm, std::abs(d));
      ++e.compared;
    }
  e.rms_mm = e.compared ? std::sqrt(sum2 / e.compared) : INFINITY;
  e.valid_share = interior ? static_cast<double>(e.compared) / interior : 0.0;
  return e;
}

}  // namespace gvkit::capture::fixture
