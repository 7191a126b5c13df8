#include "gvkit/player/frame_range.hpp"

#include <gtest/gtest.h>

namespace gvkit::player {
namespace {

std::vector<int64_t> select(const std::string& text, int64_t n) {
  auto r = parse_frame_range(text);
  EXPECT_TRUE(r.is_ok()) << text << ": " << r.status().message();
  auto i = r->indices(n);
  EXPECT_TRUE(i.is_ok()) << text << ": " << i.status().message();
  return i.is_ok() ? *i : std::vector<int64_t>{};
}

TEST(FrameRange, ParsesSlicesAndSingleFrames) {
  EXPECT_EQ(select("1:4", 10), (std::vector<int64_t>{1, 2, 3}));
  EXPECT_EQ(select("7:", 10), (std::vector<int64_t>{7, 8, 9}));
  EXPECT_EQ(select(":2", 10), (std::vector<int64_t>{0, 1}));
  EXPECT_EQ(select(":", 3), (std::vector<int64_t>{0, 1, 2}));
  EXPECT_EQ(select("5", 10), (std::vector<int64_t>{5}));
  EXPECT_EQ(select("8:100", 10), (std::vector<int64_t>{8, 9}));  // clipped to the sequence
}

TEST(FrameRange, RejectsNonsenseAndEmptySelections) {
  for (const char* bad : {"", "a:b", "-1:3", "3:1", "2:2", "1:2:3", "x"})
    EXPECT_FALSE(parse_frame_range(bad).is_ok()) << bad;
  auto far = parse_frame_range("20:");
  ASSERT_TRUE(far.is_ok());
  auto none = far->indices(10);
  ASSERT_FALSE(none.is_ok());
  EXPECT_NE(none.status().message().find("10-frame"), std::string::npos);
}

}  // namespace
}  // namespace gvkit::player
