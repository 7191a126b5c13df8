#include "gvkit/player/geometry_image_preview.hpp"

#include <algorithm>
#include <cmath>

#include "gvkit/core/status.hpp"

namespace gvkit::player {

cv::Mat geometry_image_preview_rgb(const GeometryImage& image) {
  GVKIT_CHECK(image.check().is_ok(), image.check().message());
  cv::Vec3f lo(INFINITY, INFINITY, INFINITY), hi(-INFINITY, -INFINITY, -INFINITY);
  for (int y = 0; y < image.xyz_mm.rows; ++y)
    for (int x = 0; x < image.xyz_mm.cols; ++x) {
      if (!image.domain_mask.at<uint8_t>(y, x)) continue;
      const cv::Vec3f p = image.xyz_mm.at<cv::Vec3f>(y, x);
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
    }
  cv::Mat rgb(image.xyz_mm.size(), CV_8UC3, cv::Scalar(40, 40, 40));
  for (int y = 0; y < rgb.rows; ++y)
    for (int x = 0; x < rgb.cols; ++x) {
      if (!image.domain_mask.at<uint8_t>(y, x)) continue;
      const cv::Vec3f p = image.xyz_mm.at<cv::Vec3f>(y, x);
      cv::Vec3b& out = rgb.at<cv::Vec3b>(y, x);
      for (int k = 0; k < 3; ++k) {
        const float range = hi[k] - lo[k];
        out[k] =
            static_cast<uint8_t>(range > 0 ? std::lround(255.0f * (p[k] - lo[k]) / range) : 128);
      }
    }
  return rgb;
}

}  // namespace gvkit::player
