#pragma once
// Bjontegaard delta rate with piecewise cubic (monotone Hermite) interpolation of log10(rate)
// over PSNR, integrated over the PSNR interval both curves cover.

#include <optional>
#include <vector>

namespace gvkit::bench {

struct RdPoint {
  double rate;  // bits per vertex (any rate unit, the same for both curves)
  double psnr_db;
};

// Average rate difference of `test` against `anchor` in percent (negative = test needs fewer
// bits), or nothing when the curves share no PSNR interval or have fewer than 2 points each.
std::optional<double> bd_rate_percent(std::vector<RdPoint> anchor, std::vector<RdPoint> test);

}  // namespace gvkit::bench
