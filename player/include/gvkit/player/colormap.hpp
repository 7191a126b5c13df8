#pragma once
// The heat-map colour scale of the error view (Turbo: dark blue = 0, dark red = max) and its
// colour bar, drawn onto rendered pictures.

#include <string>

#include <opencv2/core.hpp>

namespace gvkit::player {

// Turbo colour of t (clamped to [0, 1]) as RGB in [0, 1] (polynomial fit of the Turbo map).
cv::Vec3f turbo_rgb(float t);

// Draws a vertical colour bar 0..max_mm with tick labels in mm at the right edge of a CV_8UC3
// BGR picture (needs >= 120 px height; smaller pictures are left unchanged).
void draw_colour_bar(cv::Mat& bgr, double max_mm, const std::string& title = "error (mm)");

}  // namespace gvkit::player
