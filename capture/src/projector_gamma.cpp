#include "gvkit/capture/projector_gamma.hpp"

#include <cmath>

namespace gvkit::capture {
namespace {

// Least-squares offset and gain for a given gamma; returns the residual sum of squares.
double fit_linear(const std::vector<double>& v, const std::vector<double>& mean, double gamma,
                  double& offset, double& gain) {
  const int n = static_cast<int>(v.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int i = 0; i < n; ++i) {
    const double x = std::pow(v[i], gamma);
    sx += x;
    sy += mean[i];
    sxx += x * x;
    sxy += x * mean[i];
  }
  const double det = n * sxx - sx * sx;
  gain = det != 0 ? (n * sxy - sx * sy) / det : 0;
  offset = (sy - gain * sx) / n;
  double rss = 0;
  for (int i = 0; i < n; ++i) {
    const double r = offset + gain * std::pow(v[i], gamma) - mean[i];
    rss += r * r;
  }
  return rss;
}

}  // namespace

std::vector<double> gamma_calibration_levels(int count) {
  GVKIT_CHECK(count >= 5, "at least 5 levels");
  std::vector<double> levels(count);
  for (int i = 0; i < count; ++i) levels[i] = static_cast<double>(i) / (count - 1);
  return levels;
}

std::vector<cv::Mat> gamma_calibration_patterns(cv::Size projector_size, int count) {
  std::vector<cv::Mat> patterns;
  for (double v : gamma_calibration_levels(count))
    patterns.emplace_back(projector_size, CV_32F, cv::Scalar(v));
  return patterns;
}

Result<GammaEstimate> estimate_projector_gamma(const std::vector<double>& levels,
                                               const std::vector<cv::Mat>& images,
                                               double min_contrast) {
  if (levels.size() != images.size())
    return invalid_argument("gamma calibration: " + std::to_string(images.size()) + " images for " +
                            std::to_string(levels.size()) + " levels");
  if (levels.size() < 5) return invalid_argument("gamma calibration: needs at least 5 levels");
  for (size_t i = 0; i < images.size(); ++i)
    if (images[i].empty() || images[i].channels() != 1 ||
        (images[i].depth() != CV_8U && images[i].depth() != CV_16U) ||
        images[i].size() != images[0].size() || images[i].depth() != images[0].depth())
      return invalid_argument("gamma calibration: image " + std::to_string(i) +
                              " is not 8/16-bit grey of the first image's size and depth");
  const double range = images[0].depth() == CV_16U ? 65535.0 : 255.0;
  std::vector<cv::Mat> f(images.size());
  for (size_t i = 0; i < images.size(); ++i) images[i].convertTo(f[i], CV_32F, 1.0 / range);
  cv::Mat lo = f[0].clone(), hi = f[0].clone();
  for (const cv::Mat& m : f) {
    lo = cv::min(lo, m);
    hi = cv::max(hi, m);
  }
  const cv::Mat usable = ((hi - lo) >= min_contrast) & (hi < 0.995f);
  GammaEstimate e;
  e.pixels = cv::countNonZero(usable);
  if (e.pixels < 100)
    return failed_precondition("gamma calibration: only " + std::to_string(e.pixels) +
                               " pixels respond to the projector (need 100)");
  // Each pixel is normalised to its own dark and bright response, so albedo and shading
  // drop out; the per-level mean is then offset + gain v^gamma with offset ~0, gain ~1.
  std::vector<double> mean(levels.size(), 0.0);
  for (size_t i = 0; i < f.size(); ++i) {
    cv::Mat normalised = (f[i] - lo) / (hi - lo);
    mean[i] = cv::mean(normalised, usable)[0];
  }
  // Golden-section search on gamma.
  double a = 0.2, b = 5.0;
  const double phi = 0.5 * (std::sqrt(5.0) - 1);
  double o, g;
  for (int it = 0; it < 80; ++it) {
    const double c = b - phi * (b - a), d = a + phi * (b - a);
    if (fit_linear(levels, mean, c, o, g) < fit_linear(levels, mean, d, o, g))
      b = d;
    else
      a = c;
  }
  e.gamma = 0.5 * (a + b);
  e.rms_residual = std::sqrt(fit_linear(levels, mean, e.gamma, e.offset, e.gain) / levels.size());
  if (e.gamma < 0.21 || e.gamma > 4.99)
    return failed_precondition(
        "gamma calibration: the response does not fit a gamma curve "
        "(estimate at the search limit " +
        std::to_string(e.gamma) + ")");
  return e;
}

void compensate_gamma(std::vector<cv::Mat>& patterns, double gamma) {
  GVKIT_CHECK(gamma > 0);
  for (cv::Mat& p : patterns) {
    GVKIT_CHECK(p.type() == CV_32F);
    cv::Mat clipped = cv::max(cv::min(p, 1.0), 0.0);
    cv::pow(clipped, 1.0 / gamma, p);
  }
}

}  // namespace gvkit::capture
