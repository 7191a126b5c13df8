#include "gvkit/player/contact_sheet.hpp"

#include <gtest/gtest.h>

#include "gvkit/core/status.hpp"

namespace gvkit::player {
namespace {

TEST(ContactSheet, TilesLandInTheirGridCells) {
  std::vector<cv::Mat> tiles;
  for (int i = 0; i < 5; ++i) tiles.emplace_back(20, 30, CV_8UC3, cv::Scalar(i * 40, 0, 0));
  const cv::Mat sheet = contact_sheet(tiles, {}, 2);
  ASSERT_EQ(sheet.size(), cv::Size(2 * 30 + 3 * 2, 3 * 20 + 4 * 2));
  // Tile 3 is row 1, column 1.
  EXPECT_EQ(sheet.at<cv::Vec3b>(2 + 22 + 10, 2 + 32 + 15), cv::Vec3b(120, 0, 0));
  // The missing sixth cell stays white.
  EXPECT_EQ(sheet.at<cv::Vec3b>(2 + 44 + 10, 2 + 32 + 15), cv::Vec3b(255, 255, 255));
  EXPECT_THROW(contact_sheet({}, {}, 2), ContractError);
}

TEST(ContactSheet, EvenlySpacedKeepsFirstAndLast) {
  EXPECT_EQ(evenly_spaced(10, 4), (std::vector<size_t>{0, 3, 6, 9}));
  EXPECT_EQ(evenly_spaced(3, 8), (std::vector<size_t>{0, 1, 2}));
  EXPECT_EQ(evenly_spaced(5, 1), (std::vector<size_t>{0}));
  EXPECT_TRUE(evenly_spaced(0, 3).empty());
}

}  // namespace
}  // namespace gvkit::player
