#pragma once
// Projector response (gamma): estimation from a calibration sequence and compensation by a
// look-up table applied to the patterns before projection. A projector with response
// I = value^gamma bends sinusoids, which N-step decoding turns into a phase error at N times
// the fringe frequency (waviness); 3-step suffers most.
//
// Calibration sequence: uniform projector images at `levels` values in [0, 1]
// (gamma_calibration_levels()), each seen by the camera on a static scene. The response
// I(v) = offset + gain * v^gamma is fitted per pixel-averaged level.

#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/status.hpp"

namespace gvkit::capture {

struct GammaEstimate {
  double gamma = 1;
  double offset = 0, gain = 1;  // camera intensity (normalised to [0, 1]) = offset + gain v^gamma
  double rms_residual = 0;      // of the fit, in normalised intensity
  int pixels = 0;               // pixels used (lit by the projector in every image)
};

// `count` equally spaced levels from 0 to 1 (count >= 5).
std::vector<double> gamma_calibration_levels(int count = 17);
// The uniform projector images of those levels, CV_32F.
std::vector<cv::Mat> gamma_calibration_patterns(cv::Size projector_size, int count = 17);

// Fits the response from camera images (CV_8U/CV_16U, one per level, same size). Pixels whose
// brightest-minus-darkest response is below min_contrast of the range (shadow, background) or
// that saturate are ignored. Fails naming the problem: counts differ, sizes differ, fewer than
// 100 usable pixels, or a fit outside gamma in [0.2, 5].
Result<GammaEstimate> estimate_projector_gamma(const std::vector<double>& levels,
                                               const std::vector<cv::Mat>& images,
                                               double min_contrast = 0.05);

// Sends each pattern value v as v^(1/gamma), so the projector emits v (in place; CV_32F).
void compensate_gamma(std::vector<cv::Mat>& patterns, double gamma);

}  // namespace gvkit::capture
