#pragma once
// Reads a session folder written by SessionWriter (session_info.hpp).

#include <filesystem>
#include <optional>

#include "gvkit/capture/session_info.hpp"
#include "gvkit/core/calibration.hpp"
#include "gvkit/core/fringe_set.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

class SessionReader {
 public:
  // Reads session.json and the calibration. Fails naming the file that is missing or wrong.
  static Result<SessionReader> open(const std::filesystem::path& dir);

  const SessionInfo& info() const { return info_; }
  const Calibration& calibration() const { return calibration_; }
  size_t frame_count() const { return info_.frames.size(); }

  // The images of the i-th listed frame. Fails naming the image file.
  Result<FringeSet> read_frame(size_t i) const;
  // gt/frame_NNNNNN.exr of a frame index when the session has ground truth and the file exists.
  std::optional<std::filesystem::path> ground_truth_path(int64_t index) const;

  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  SessionInfo info_;
  Calibration calibration_;
};

}  // namespace gvkit::capture
