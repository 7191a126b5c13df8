#pragma once
// Bjontegaard delta rate with piecewise cubic (monotone Hermite) interpolation of log10(rate)
// over PSNR, integrated over the PSNR interval both curves cover; and the same over the normal
// error (codec/surface_metrics.hpp) with quality = -20 log10(normal p95 / 1 degree): monotone in
// the error, and a halving of the p95 counts the same (6.02 "dB") wherever it happens.

#include <cmath>
#include <optional>
#include <vector>

namespace gvkit::bench {

struct RdPoint {
  double rate;  // bits per vertex (any rate unit, the same for both curves)
  double psnr_db;
  double normal_db = NAN;  // -20 log10(normal p95 / 1 degree); NaN where not measured
};

// The normal-error quality of a 95th-percentile normal error (degrees, floored at 0.001).
double normal_quality_db(double normal_p95_deg);

// Average rate difference of `test` against `anchor` in percent (negative = test needs fewer
// bits), or nothing when the curves share no PSNR interval or have fewer than 2 points each.
std::optional<double> bd_rate_percent(std::vector<RdPoint> anchor, std::vector<RdPoint> test);

// The same over the normal error (normal_db as the quality axis); nothing also when a point of
// either curve has no normal error.
std::optional<double> bd_rate_normal_percent(std::vector<RdPoint> anchor,
                                             std::vector<RdPoint> test);

}  // namespace gvkit::bench
