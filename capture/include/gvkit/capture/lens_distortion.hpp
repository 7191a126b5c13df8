#pragma once
// OpenCV's lens model (k1 k2 p1 p2 [k3 [k4 k5 k6]]) on normalized image coordinates, inline for
// the per-pixel kernels. Coefficient vectors of 0, 4, 5 or 8 entries are supported here.

#include <vector>

namespace gvkit::capture {

struct LensDistortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0, k4 = 0, k5 = 0, k6 = 0;
  bool none = true;

  // False (and no change) when the vector has 12 or 14 coefficients (thin prism / tilt).
  bool set(const std::vector<double>& d) {
    if (!(d.empty() || d.size() == 4 || d.size() == 5 || d.size() == 8)) return false;
    double* f[8] = {&k1, &k2, &p1, &p2, &k3, &k4, &k5, &k6};
    for (int i = 0; i < 8; ++i) *f[i] = i < static_cast<int>(d.size()) ? d[i] : 0.0;
    none = true;
    for (double v : d) none = none && v == 0.0;
    return true;
  }

  // Undistorted normalized (x, y) -> distorted normalized (xd, yd).
  void apply(double x, double y, double& xd, double& yd) const {
    const double r2 = x * x + y * y;
    const double radial =
        (1 + r2 * (k1 + r2 * (k2 + r2 * k3))) / (1 + r2 * (k4 + r2 * (k5 + r2 * k6)));
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  }
};

}  // namespace gvkit::capture
