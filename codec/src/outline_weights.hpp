#pragma once
// Encoder only: the per-sample SSD weights of EncoderOptions::outline_weight
// (PlaneCodingParams::distortion_weights), from the domain mask at the coded resolution.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace gvkit::codec {

// padded_width x padded_height weights (row-major): `weight` at the mask's outline pixels
// (inside the domain, with a 4-neighbour outside it or outside the mask's image), 1 elsewhere,
// the padding included. mask: CV_8U, at most padded_width x padded_height (contract).
std::vector<uint8_t> outline_weights(const cv::Mat& mask, int padded_width, int padded_height,
                                     int weight);

}  // namespace gvkit::codec
