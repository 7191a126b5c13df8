// Reads a structured-light calibration (gvkit or SLStudio format) and prints the rig's geometry.
//   calibration_summary calibration.xml
#include <cmath>
#include <cstdio>

#include <gvkit/core/calibration_io.hpp>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CALIBRATION\n", argv[0]);
    return 2;
  }
  const gvkit::Result<gvkit::LoadedCalibration> loaded = gvkit::read_calibration(argv[1]);
  if (!loaded.is_ok()) {
    std::fprintf(stderr, "error: %s\n", loaded.status().message().c_str());
    return 1;
  }
  const gvkit::Calibration& c = loaded->calibration;
  const double fov_deg = 2 * std::atan(0.5 * c.camera_width / c.camera_K(0, 0)) * 180 / CV_PI;
  std::printf("camera %dx%d, horizontal field of view %.1f deg\n", c.camera_width, c.camera_height,
              fov_deg);
  std::printf("projector %dx%d\n", c.projector_width, c.projector_height);
  std::printf("baseline %.1f mm\n", c.baseline_mm());
  return 0;
}
