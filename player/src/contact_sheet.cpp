#include "gvkit/player/contact_sheet.hpp"

#include <opencv2/imgproc.hpp>

#include "gvkit/core/status.hpp"

namespace gvkit::player {

cv::Mat contact_sheet(const std::vector<cv::Mat>& tiles, const std::vector<std::string>& labels,
                      int columns) {
  GVKIT_CHECK(!tiles.empty() && columns >= 1, "contact sheet needs tiles and columns >= 1");
  const cv::Size size = tiles.front().size();
  const int gutter = 2;
  const int cols = std::min<int>(columns, static_cast<int>(tiles.size()));
  const int rows = static_cast<int>((tiles.size() + cols - 1) / cols);
  cv::Mat sheet(rows * (size.height + gutter) + gutter, cols * (size.width + gutter) + gutter,
                CV_8UC3, cv::Scalar(255, 255, 255));
  const double scale = std::clamp(size.height / 400.0, 0.35, 1.0);
  for (size_t i = 0; i < tiles.size(); ++i) {
    GVKIT_CHECK(tiles[i].size() == size && tiles[i].type() == CV_8UC3, "tiles of one size, BGR");
    const int r = static_cast<int>(i) / cols, c = static_cast<int>(i) % cols;
    const cv::Rect roi(gutter + c * (size.width + gutter), gutter + r * (size.height + gutter),
                       size.width, size.height);
    tiles[i].copyTo(sheet(roi));
    if (i < labels.size())
      cv::putText(sheet, labels[i], roi.tl() + cv::Point(6, static_cast<int>(22 * scale) + 4),
                  cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(40, 40, 40), 1, cv::LINE_AA);
  }
  return sheet;
}

std::vector<size_t> evenly_spaced(size_t total, size_t count) {
  std::vector<size_t> out;
  if (total == 0 || count == 0) return out;
  if (count >= total || count == 1) {
    for (size_t i = 0; i < (count == 1 ? 1 : total); ++i) out.push_back(i);
    return out;
  }
  for (size_t k = 0; k < count; ++k) out.push_back(k * (total - 1) / (count - 1));
  return out;
}

}  // namespace gvkit::player
