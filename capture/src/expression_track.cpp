#include "gvkit/capture/expression_track.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace gvkit::capture {
namespace {

constexpr double kTwoPi = 6.283185307179586;

// 0..1 bump of width `width` seconds repeating every `period` seconds.
double pulse(double t, double period, double width, double phase) {
  const double local = std::fmod(t + phase * period / kTwoPi, period);
  if (local < 0 || local > width) return 0.0;
  return std::sin(CV_PI * local / width);
}

double smooth01(double x) { return 0.5 - 0.5 * std::cos(CV_PI * std::clamp(x, 0.0, 1.0)); }

}  // namespace

std::vector<std::string> expression_track_names() {
  return {"neutral", "talk", "smile", "surprise", "blink", "mix"};
}

Result<ExpressionTrack> ExpressionTrack::create(const std::string& name, uint64_t seed,
                                                bool head_motion) {
  const auto names = expression_track_names();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    return invalid_argument("expression track '" + name + "' is unknown; known: " + list);
  }
  ExpressionTrack track;
  track.name_ = name;
  track.head_motion_ = head_motion;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> phase(0, kTwoPi), rate(0.85, 1.15);
  for (double& p : track.phase_) p = phase(rng);
  for (double& r : track.rate_) r = rate(rng);
  return track;
}

ExpressionPose ExpressionTrack::at(double t) const {
  ExpressionPose pose;
  auto& w = pose.weights;
  const bool mix = name_ == "mix";
  if (name_ == "talk" || mix) {
    // Syllables at ~4 Hz modulated by a slower phrase rhythm.
    const double syllable = 0.5 + 0.5 * std::sin(kTwoPi * 4.0 * rate_[0] * t + phase_[0]);
    const double phrase = smooth01(0.5 + 0.8 * std::sin(kTwoPi * 0.35 * rate_[1] * t + phase_[1]));
    w["jawOpen"] = 0.45 * syllable * phrase;
    w["mouthFunnel"] = 0.3 * phrase * std::max(0.0, std::sin(kTwoPi * 1.7 * t + phase_[2]));
    w["mouthPucker"] = 0.25 * phrase * std::max(0.0, std::sin(kTwoPi * 1.1 * t + phase_[3]));
  }
  if (name_ == "smile" || mix) {
    const double s = smooth01(0.5 + 0.9 * std::sin(kTwoPi * 0.25 * rate_[2] * t + phase_[4]));
    const double amount = mix ? 0.6 * s : 0.9 * s;
    w["mouthSmile_L"] = amount;
    w["mouthSmile_R"] = amount * 0.95;
    w["cheekPuff_L"] = 0.1 * amount;
    w["cheekPuff_R"] = 0.1 * amount;
  }
  if (name_ == "surprise" || (mix && std::fmod(t + 2.0, 6.0) < 2.0)) {
    const double s = name_ == "surprise"
                         ? smooth01(0.5 + 0.9 * std::sin(kTwoPi * 0.3 * rate_[3] * t + phase_[5]))
                         : pulse(t + 2.0, 6.0, 2.0, 0.0);
    w["browInnerUp_L"] = 0.9 * s;
    w["browInnerUp_R"] = 0.9 * s;
    w["jawOpen"] = std::max(w.count("jawOpen") ? w["jawOpen"] : 0.0, 0.5 * s);
  }
  if (name_ == "blink" || mix) {
    const double b = pulse(t, 3.0 * rate_[0], 0.25, phase_[6]);
    w["eyeBlink_L"] = b;
    w["eyeBlink_R"] = b;
  }
  if (head_motion_) {
    pose.head_rotation_deg = cv::Vec3d(8.0 * std::sin(kTwoPi * 0.2 * t + phase_[7]),
                                       4.0 * std::sin(kTwoPi * 0.27 * t + phase_[5]),
                                       2.0 * std::sin(kTwoPi * 0.13 * t + phase_[3]));
    pose.head_translation_mm = cv::Vec3d(10.0 * std::sin(kTwoPi * 0.11 * t + phase_[1]), 0,
                                         15.0 * std::sin(kTwoPi * 0.07 * t + phase_[2]));
  }
  return pose;
}

}  // namespace gvkit::capture
