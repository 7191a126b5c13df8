#pragma once
// A contact sheet: pictures of several frames in a grid, each labelled, in one PNG-ready image.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace gvkit::player {

// Tiles (CV_8UC3, one size, non-empty, contract) laid out row by row, `columns` per row (>= 1),
// with a label drawn at each tile's top-left corner and a 2 px white gutter.
cv::Mat contact_sheet(const std::vector<cv::Mat>& tiles, const std::vector<std::string>& labels,
                      int columns);

// `count` positions spread evenly over 0..total-1 (first and last included); all when fewer.
std::vector<size_t> evenly_spaced(size_t total, size_t count);

}  // namespace gvkit::player
