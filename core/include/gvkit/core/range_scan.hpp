#pragma once
// RangeScan: one reconstructed frame, a per-camera-pixel measurement (capture -> facemap).

#include <cstdint>

#include <opencv2/core.hpp>

#include "gvkit/core/status.hpp"
#include "gvkit/core/timestamp.hpp"

namespace gvkit {

struct RangeScan {
  cv::Mat xyz_mm;   // CV_32FC3, H x W, camera frame (mm); NaN where invalid
  cv::Mat texture;  // CV_32F, H x W, in [0, 1]
  cv::Mat valid;    // CV_8U, H x W, 255 = measured, 0 = not
  cv::Mat quality;  // CV_32F, H x W, fringe modulation (same units as the input intensities / max)
  int64_t index = 0;
  Timestamp timestamp{0};

  cv::Size size() const { return xyz_mm.size(); }
  // Share of valid pixels in [0, 1].
  double valid_fraction() const;
  // Ok when the planes have the documented types and one size, and valid pixels have finite xyz.
  Status check() const;
};

}  // namespace gvkit
