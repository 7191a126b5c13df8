#pragma once
// Calibration files. gvkit's own format is an OpenCV FileStorage (YAML, JSON or XML by extension)
// with the fields of Calibration; SLStudio's calibration.xml (Kc, kc, Kp, kp, Rp, Tp with
// Rp, Tp = proj_from_cam, frameWidth/Height, screenResX/Y) is recognised and converted.

#include <filesystem>

#include "gvkit/core/calibration.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit {

enum class CalibrationFormat { kGvkit, kSlStudio };

struct LoadedCalibration {
  Calibration calibration;
  CalibrationFormat format = CalibrationFormat::kGvkit;
};

// Reads either format and checks it (Calibration::check()). Fails naming the file and the
// missing or non-finite field.
Result<LoadedCalibration> read_calibration(const std::filesystem::path& path);
// Writes gvkit's format (.yaml/.yml/.json/.xml), atomically.
Status write_calibration(const std::filesystem::path& path, const Calibration& calibration);

}  // namespace gvkit
