#pragma once
// GeometryImage: a W x H sampling of the canonical face domain D whose pixels are xyz
// positions (facemap -> codec, codec -> player).

#include <cstdint>

#include <opencv2/core.hpp>

#include "gvkit/core/status.hpp"
#include "gvkit/core/timestamp.hpp"

namespace gvkit {

struct GeometryImage {
  cv::Mat xyz_mm;       // CV_32FC3, H x W (mm); values outside the domain are unspecified
  cv::Mat texture;      // CV_32F in [0, 1], H x W, or empty
  cv::Mat domain_mask;  // CV_8U, H x W, 255 inside D; identical for every frame of a video
  int64_t index = 0;
  Timestamp timestamp{0};

  cv::Size size() const { return xyz_mm.size(); }
  // Ok when types and sizes are as documented and every domain pixel is finite.
  Status check() const;
};

}  // namespace gvkit
