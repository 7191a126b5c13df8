#pragma once
// Small synthetic geometry videos for the player tests: a face-like bump in the camera frame
// (x right, y down, z forward, surface ~650 mm away facing the camera) with two eye holes and a
// mouth hole, animated by a frame-dependent "jaw" so consecutive frames differ.

#include <cmath>
#include <filesystem>

#include <opencv2/core.hpp>

#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/geometry_image.hpp"

namespace gvkit::player::testing {

inline bool in_ellipse(double u, double v, double cu, double cv, double ru, double rv) {
  const double a = (u - cu) / ru, b = (v - cv) / rv;
  return a * a + b * b <= 1.0;
}

// size x size image covering a 160 x 160 mm patch; holes when `holes`.
inline GeometryImage make_face_like_image(int size, int frame, bool holes = true) {
  GeometryImage image;
  image.xyz_mm.create(size, size, CV_32FC3);
  image.texture.create(size, size, CV_32F);
  image.domain_mask.create(size, size, CV_8U);
  const double jaw = 6.0 * std::sin(frame * 0.3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double u = (x + 0.5) / size * 2 - 1, v = (y + 0.5) / size * 2 - 1;  // [-1, 1]
      const double r2 = u * u + v * v;
      double z = 650.0 - 60.0 * std::exp(-2.0 * r2) -
                 15.0 * std::exp(-30.0 * (u * u + (v + 0.05) * (v + 0.05)));
      const double y_mm = 80.0 * v + (v > 0.3 ? jaw * (v - 0.3) : 0.0);
      image.xyz_mm.at<cv::Vec3f>(y, x) =
          cv::Vec3f(80.0f * static_cast<float>(u), static_cast<float>(y_mm), static_cast<float>(z));
      image.texture.at<float>(y, x) =
          static_cast<float>(0.5 + 0.4 * std::cos(6 * u) * std::cos(6 * v));
      bool inside = r2 < 1.0;
      if (holes &&
          (in_ellipse(u, v, -0.4, -0.3, 0.18, 0.08) || in_ellipse(u, v, 0.4, -0.3, 0.18, 0.08) ||
           in_ellipse(u, v, 0.0, 0.5, 0.3, 0.06 + 0.03 * std::sin(frame * 0.3) + 0.03)))
        inside = false;
      image.domain_mask.at<uint8_t>(y, x) = inside ? 255 : 0;
    }
  image.index = frame;
  return image;
}

// Writes frames 0..count-1 as frame_NNNNNN.exr into dir.
inline void write_face_like_sequence(const std::filesystem::path& dir, int count, int size) {
  if (!ensure_directory(dir).is_ok()) throw std::runtime_error("cannot create " + dir.string());
  for (int i = 0; i < count; ++i) {
    const Status s =
        write_geometry_image_exr(frame_path(dir, i, ".exr"), make_face_like_image(size, i));
    if (!s.is_ok()) throw std::runtime_error(s.message());
  }
}

}  // namespace gvkit::player::testing
