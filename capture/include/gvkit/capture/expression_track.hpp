#pragma once
// Named expression tracks: ICT blendshape weights (and optional head motion) as smooth functions
// of time, deterministic from a seed. Tracks: neutral, talk (jaw and lips at speech rate), smile
// (slow smiles), surprise (brows up, jaw drop), blink (periodic blinks), mix (talk + blink with
// smiles and surprise in turn; the default).

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/status.hpp"

namespace gvkit::capture {

struct ExpressionPose {
  std::map<std::string, double> weights;  // blendshape name -> weight in [0, 1]
  cv::Vec3d head_rotation_deg{0, 0, 0};   // yaw, pitch, roll about the head centre
  cv::Vec3d head_translation_mm{0, 0, 0};
};

// The track names, for --help and validation.
std::vector<std::string> expression_track_names();

class ExpressionTrack {
 public:
  // Fails naming the track when it is unknown.
  static Result<ExpressionTrack> create(const std::string& name, uint64_t seed,
                                        bool head_motion = false);
  // The pose at time t (seconds from the start).
  ExpressionPose at(double t_s) const;
  const std::string& name() const { return name_; }

 private:
  std::string name_;
  bool head_motion_ = false;
  double phase_[8] = {};  // random phases (rad) from the seed
  double rate_[4] = {};   // random rate factors near 1
};

}  // namespace gvkit::capture
