#include "gvkit/codec/geometry_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gvkit::codec {

double GeometryError::psnr_db(double peak_mm) const {
  if (rms_mm <= 0) return std::numeric_limits<double>::infinity();
  return 20.0 * std::log10(peak_mm / rms_mm);
}

GeometryError geometry_error(const GeometryImage& reference, const GeometryImage& decoded) {
  GVKIT_CHECK(reference.xyz_mm.size() == decoded.xyz_mm.size() &&
              reference.xyz_mm.type() == CV_32FC3 && decoded.xyz_mm.type() == CV_32FC3);
  GeometryError e;
  for (int y = 0; y < reference.xyz_mm.rows; ++y) {
    const cv::Vec3f* a = reference.xyz_mm.ptr<cv::Vec3f>(y);
    const cv::Vec3f* b = decoded.xyz_mm.ptr<cv::Vec3f>(y);
    const uint8_t* m = reference.domain_mask.ptr<uint8_t>(y);
    for (int x = 0; x < reference.xyz_mm.cols; ++x) {
      if (!m[x]) continue;
      double d2 = 0;
      for (int k = 0; k < 3; ++k) {
        const double d = static_cast<double>(a[x][k]) - b[x][k];
        d2 += d * d;
      }
      e.sum_squared_mm2 += d2;
      e.max_mm = std::max(e.max_mm, std::sqrt(d2));
      ++e.pixels;
    }
  }
  e.rms_mm = e.pixels ? std::sqrt(e.sum_squared_mm2 / e.pixels) : 0;
  return e;
}

void accumulate(GeometryError& total, const GeometryError& frame) {
  total.sum_squared_mm2 += frame.sum_squared_mm2;
  total.pixels += frame.pixels;
  total.max_mm = std::max(total.max_mm, frame.max_mm);
  total.rms_mm = total.pixels ? std::sqrt(total.sum_squared_mm2 / total.pixels) : 0;
}

}  // namespace gvkit::codec
