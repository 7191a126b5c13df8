#include "bd_rate.hpp"

#include <algorithm>
#include <cmath>

namespace gvkit::bench {
namespace {

// Monotone piecewise cubic (Fritsch-Carlson) through (x[i], y[i]), x increasing.
class Pchip {
 public:
  Pchip(std::vector<double> x, std::vector<double> y) : x_(std::move(x)), y_(std::move(y)) {
    const size_t n = x_.size();
    std::vector<double> h(n - 1), delta(n - 1);
    for (size_t i = 0; i + 1 < n; ++i) {
      h[i] = x_[i + 1] - x_[i];
      delta[i] = (y_[i + 1] - y_[i]) / h[i];
    }
    d_.assign(n, 0.0);
    if (n == 2) {
      d_[0] = d_[1] = delta[0];
      return;
    }
    for (size_t i = 1; i + 1 < n; ++i) {
      if (delta[i - 1] * delta[i] <= 0) continue;
      const double w1 = 2 * h[i] + h[i - 1], w2 = h[i] + 2 * h[i - 1];
      d_[i] = (w1 + w2) / (w1 / delta[i - 1] + w2 / delta[i]);
    }
    d_[0] = end_slope(h[0], h[1], delta[0], delta[1]);
    d_[n - 1] = end_slope(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);
  }
  double operator()(double x) const {
    size_t i = 0;
    while (i + 2 < x_.size() && x > x_[i + 1]) ++i;
    const double h = x_[i + 1] - x_[i], t = (x - x_[i]) / h;
    const double h00 = (1 + 2 * t) * (1 - t) * (1 - t), h10 = t * (1 - t) * (1 - t);
    const double h01 = t * t * (3 - 2 * t), h11 = t * t * (t - 1);
    return h00 * y_[i] + h10 * h * d_[i] + h01 * y_[i + 1] + h11 * h * d_[i + 1];
  }

 private:
  static double end_slope(double h0, double h1, double d0, double d1) {
    double d = ((2 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if (d * d0 <= 0) return 0;
    if (d0 * d1 <= 0 && std::abs(d) > std::abs(3 * d0)) return 3 * d0;
    return d;
  }
  std::vector<double> x_, y_, d_;
};

std::optional<Pchip> log_rate_of_psnr(std::vector<RdPoint> c, double* lo, double* hi) {
  std::sort(c.begin(), c.end(), [](auto a, auto b) { return a.psnr_db < b.psnr_db; });
  std::vector<double> x, y;
  for (const RdPoint& p : c) {
    if (!(p.rate > 0) || !std::isfinite(p.psnr_db)) continue;
    if (!x.empty() && p.psnr_db <= x.back() + 1e-9) continue;
    x.push_back(p.psnr_db);
    y.push_back(std::log10(p.rate));
  }
  if (x.size() < 2) return std::nullopt;
  *lo = x.front();
  *hi = x.back();
  return Pchip(x, y);
}

}  // namespace

std::optional<double> bd_rate_percent(std::vector<RdPoint> anchor, std::vector<RdPoint> test) {
  double alo, ahi, tlo, thi;
  auto a = log_rate_of_psnr(std::move(anchor), &alo, &ahi);
  auto t = log_rate_of_psnr(std::move(test), &tlo, &thi);
  if (!a || !t) return std::nullopt;
  const double lo = std::max(alo, tlo), hi = std::min(ahi, thi);
  if (hi <= lo) return std::nullopt;
  const int steps = 2000;
  double sum = 0;
  for (int i = 0; i < steps; ++i) {
    const double p = lo + (hi - lo) * (i + 0.5) / steps;
    sum += (*t)(p) - (*a)(p);
  }
  return (std::pow(10.0, sum / steps) - 1.0) * 100.0;
}

double normal_quality_db(double normal_p95_deg) {
  return -20.0 * std::log10(std::max(1e-3, normal_p95_deg));
}

std::optional<double> bd_rate_normal_percent(std::vector<RdPoint> anchor,
                                             std::vector<RdPoint> test) {
  for (auto* curve : {&anchor, &test})
    for (RdPoint& p : *curve) {
      if (!std::isfinite(p.normal_db)) return std::nullopt;
      p.psnr_db = p.normal_db;
    }
  return bd_rate_percent(std::move(anchor), std::move(test));
}

}  // namespace gvkit::bench
