#include "outline_weights.hpp"

#include "gvkit/core/status.hpp"

namespace gvkit::codec {

std::vector<uint8_t> outline_weights(const cv::Mat& mask, int padded_width, int padded_height,
                                     int weight) {
  GVKIT_CHECK(mask.type() == CV_8U && mask.cols <= padded_width && mask.rows <= padded_height &&
              weight >= 1 && weight <= 255);
  std::vector<uint8_t> weights(static_cast<size_t>(padded_width) * padded_height, 1);
  const auto inside = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask.at<uint8_t>(y, x) != 0;
  };
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x)
      if (inside(x, y) &&
          (!inside(x - 1, y) || !inside(x + 1, y) || !inside(x, y - 1) || !inside(x, y + 1)))
        weights[static_cast<size_t>(y) * padded_width + x] = static_cast<uint8_t>(weight);
  return weights;
}

}  // namespace gvkit::codec
