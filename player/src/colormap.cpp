#include "gvkit/player/colormap.hpp"

#include <algorithm>
#include <cstdio>

#include <opencv2/imgproc.hpp>

namespace gvkit::player {

cv::Vec3f turbo_rgb(float t) {
  t = std::clamp(t, 0.0f, 1.0f);
  // Polynomial approximation of Turbo (the same coefficients as the fragment shader's).
  const float t2 = t * t, t3 = t2 * t, t4 = t3 * t, t5 = t4 * t;
  const float r = 0.13572138f + 4.61539260f * t - 42.66032258f * t2 + 132.13108234f * t3 -
                  152.94239396f * t4 + 59.28637943f * t5;
  const float g = 0.09140261f + 2.19418839f * t + 4.84296658f * t2 - 14.18503333f * t3 +
                  4.27729857f * t4 + 2.82956604f * t5;
  const float b = 0.10667330f + 12.64194608f * t - 60.58204836f * t2 + 110.36276771f * t3 -
                  89.90310912f * t4 + 27.34824973f * t5;
  return {std::clamp(r, 0.0f, 1.0f), std::clamp(g, 0.0f, 1.0f), std::clamp(b, 0.0f, 1.0f)};
}

void draw_colour_bar(cv::Mat& bgr, double max_mm, const std::string& title) {
  if (bgr.empty() || bgr.type() != CV_8UC3 || bgr.rows < 120 || bgr.cols < 120) return;
  const int bar_w = std::max(10, bgr.cols / 40), bar_h = bgr.rows / 2;
  const int x0 = bgr.cols - bar_w - std::max(50, bgr.cols / 10), y0 = bgr.rows / 4;
  for (int y = 0; y < bar_h; ++y) {
    const cv::Vec3f c = turbo_rgb(1.0f - static_cast<float>(y) / (bar_h - 1));
    cv::line(bgr, {x0, y0 + y}, {x0 + bar_w - 1, y0 + y},
             cv::Scalar(255 * c[2], 255 * c[1], 255 * c[0]));
  }
  cv::rectangle(bgr, {x0 - 1, y0 - 1}, {x0 + bar_w, y0 + bar_h}, cv::Scalar(40, 40, 40));
  const double scale = std::clamp(bgr.rows / 900.0, 0.35, 1.0);
  for (int k = 0; k <= 4; ++k) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.3g", max_mm * (4 - k) / 4.0);
    cv::putText(bgr, text, {x0 + bar_w + 4, y0 + k * (bar_h - 1) / 4 + 4}, cv::FONT_HERSHEY_SIMPLEX,
                scale, cv::Scalar(30, 30, 30), 1, cv::LINE_AA);
  }
  // The title above the bar, moved left as far as it needs to end inside the picture.
  int baseline = 0;
  const int title_w = cv::getTextSize(title, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline).width;
  const int title_x = std::max(0, std::min(x0 - bar_w, bgr.cols - 4 - title_w));
  cv::putText(bgr, title, {title_x, y0 - 10}, cv::FONT_HERSHEY_SIMPLEX, scale,
              cv::Scalar(30, 30, 30), 1, cv::LINE_AA);
}

}  // namespace gvkit::player
