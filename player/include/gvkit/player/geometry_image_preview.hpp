#pragma once
// A picture of a geometry image itself (the 2D view beside the 3D one): x, y, z mapped to red,
// green, blue over the domain's bounding box; pixels outside the domain dark grey.

#include <opencv2/core.hpp>

#include "gvkit/core/geometry_image.hpp"

namespace gvkit::player {

// CV_8UC3 in RGB order (for an OpenGL texture), the image's size. image must pass check().
cv::Mat geometry_image_preview_rgb(const GeometryImage& image);

}  // namespace gvkit::player
