#pragma once
// FringeSet: the camera images of one instant under one cycle of projected patterns.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/status.hpp"
#include "gvkit/core/timestamp.hpp"

namespace gvkit {

struct FringeSet {
  std::vector<cv::Mat> images;  // N camera images, CV_8U or CV_16U, one channel, same size
  cv::Mat texture;              // optional flat-lit image (CV_8U/CV_16U/CV_32F); may be empty
  int64_t index = 0;            // frame number in the session, from 0
  Timestamp timestamp{0};       // capture time of the first image

  cv::Size size() const { return images.empty() ? cv::Size() : images.front().size(); }

  // Ok when there is at least one image and all images share size and a supported type;
  // otherwise names the first offending image ("image 2: size 640x480, expected 512x512").
  Status check() const;
};

}  // namespace gvkit
