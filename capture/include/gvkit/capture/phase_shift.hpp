#pragma once
// N-step phase-shift decoding kernels, shared by the pattern families. Image k of a set was
// projected as I = 0.5 * (1 + cos(phi - 2*pi*k/N)); the camera sees A + B*cos(phi - 2*pi*k/N).

#include <vector>

#include <opencv2/core.hpp>

namespace gvkit::capture {

// Per-pixel result of one phase-shift set. All CV_32F except saturated.
struct WrappedPhase {
  cv::Mat phase;       // wrapped phase phi in (-pi, pi]
  cv::Mat modulation;  // B, in [0, 1] of the image range
  cv::Mat mean;        // A, in [0, 1]
  cv::Mat saturated;   // CV_8U, 255 where any of the N images reached saturation_level
};

// Decodes images[first .. first + steps) (CV_8U or CV_16U, one channel, one size; checked by
// the caller). Intensities are divided by the type's maximum. steps >= 3.
WrappedPhase decode_phase_shift(const std::vector<cv::Mat>& images, int first, int steps,
                                double saturation_level);
// The plain reference of decode_phase_shift (double precision, std::atan2); same contract.
WrappedPhase decode_phase_shift_reference(const std::vector<cv::Mat>& images, int first, int steps,
                                          double saturation_level);

// atan2 by a minimax polynomial, |error| < 2e-6 rad; result in [-pi, pi]. Branch-free (selects
// only), so loops over it vectorize.
inline float fast_atan2(float y, float x) {
  const float ax = x < 0 ? -x : x, ay = y < 0 ? -y : y;
  const float mx = ax > ay ? ax : ay, mn = ax > ay ? ay : ax;
  const float a = mn / (mx + 1e-30f);
  const float s = a * a;
  float r =
      a * (0.99997726f +
           s * (-0.33262347f +
                s * (0.19354346f + s * (-0.11643287f + s * (0.05265332f - s * 0.01172120f)))));
  r = ay > ax ? 1.57079632679f - r : r;
  r = x < 0 ? 3.14159265359f - r : r;
  return y < 0 ? -r : r;
}

}  // namespace gvkit::capture
