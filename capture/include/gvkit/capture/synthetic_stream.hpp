#pragma once
// SyntheticStream: the synthetic projector-camera rig (the ICT face animated by an expression
// track, rendered by SyntheticRenderer, as `gvkit synth` does) as a live camera stream, one
// image per projected pattern, for the "synthetic:" frame source
// (FrameSourceOptions::synthetic_generator = stream->generator()).
//
// Frame i is image (i mod frames_per_cycle) of instant j = i / frames_per_cycle: with a cue, a
// white frame first, then the fringe patterns in order. Instant j shows the face at time
// j / pose_fps s. Each instant is rendered once, all its images together; the next instant is
// rendered ahead on a worker thread while the current one streams out. The ground truth of the
// latest instants is kept for recording and live accuracy checks.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "gvkit/capture/frame_source.hpp"
#include "gvkit/capture/ground_truth.hpp"
#include "gvkit/capture/synthetic_renderer.hpp"
#include "gvkit/capture/synthetic_rig.hpp"
#include "gvkit/core/calibration.hpp"
#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

struct SyntheticStreamOptions {
  std::filesystem::path ict_dir;     // ../shared/data/ict-facekit
  std::string pattern = "psp3-f16";  // create_pattern_set name
  std::string expressions = "mix";   // ExpressionTrack name
  uint64_t seed = 1;
  bool head_motion = false;
  double pose_fps = 30;           // instants per second of face motion
  double face_distance_mm = 650;  // landmark centroid depth
  bool cue = false;               // a white cue frame before the fringes of every cycle
  int keep_truth = 16;            // how many of the latest instants keep their ground truth
  SyntheticRigOptions rig;
  RenderOptions render;

  Status check() const;
  nlohmann::json to_json() const;  // as stored in session.json "source"
};

class SyntheticStream : public std::enable_shared_from_this<SyntheticStream> {
 public:
  // Loads the face model and prepares the renderer. Fails naming the ICT folder, the pattern or
  // the expression track.
  static Result<std::shared_ptr<SyntheticStream>> create(const SyntheticStreamOptions& options);
  ~SyntheticStream();
  SyntheticStream(const SyntheticStream&) = delete;
  SyntheticStream& operator=(const SyntheticStream&) = delete;

  int patterns_per_cycle() const { return patterns_per_cycle_; }
  int frames_per_cycle() const { return patterns_per_cycle_ + (options_.cue ? 1 : 0); }
  // The rig's calibration, fringe pitch set from the pattern set.
  const Calibration& calibration() const { return calibration_; }
  const SyntheticStreamOptions& options() const { return options_; }

  // The camera image of frame i (CV_8U, or CV_16U for camera bit depths > 8). Thread-safe.
  Result<cv::Mat> frame(int64_t i);
  // frame() as a FrameGenerator (holds a reference to the stream).
  FrameGenerator generator();
  // Ground truth of instant j, while it is among the keep_truth latest rendered instants.
  std::optional<GroundTruth> truth(int64_t instant) const;
  // The 68 true landmarks of instant j (any j).
  FaceLandmarks landmarks(int64_t instant) const;
  // Mean wall time of rendering one instant (all its images), ms; 0 before the first.
  double mean_render_ms() const;

 private:
  struct Impl;
  explicit SyntheticStream(std::unique_ptr<Impl> impl, const SyntheticStreamOptions& options);

  std::unique_ptr<Impl> impl_;
  SyntheticStreamOptions options_;
  Calibration calibration_;
  int patterns_per_cycle_ = 0;
};

}  // namespace gvkit::capture
