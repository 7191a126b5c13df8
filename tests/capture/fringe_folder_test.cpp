// Plain folders of fringe images: natural order, name filters, sliding windows, and messages that
// name the folder, the files and what to do when the images do not fit.
#include "gvkit/capture/fringe_folder.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "gvkit/capture/pattern_set.hpp"
#include "support/test_support.hpp"

namespace gvkit::capture {
namespace {
using testing::contains;
using testing::TempDir;
namespace fs = std::filesystem;

void write_blank(const fs::path& path, cv::Size size = {8, 6}, int depth = CV_8U, int value = 0) {
  cv::imwrite(path.string(), cv::Mat(size, depth, cv::Scalar(value)));
}

std::vector<std::string> names(const std::vector<fs::path>& paths) {
  std::vector<std::string> out;
  for (const auto& p : paths) out.push_back(p.filename().string());
  return out;
}

TEST(NaturalOrder, NumbersCompareByValue) {
  EXPECT_TRUE(natural_less("img2.png", "img10.png"));
  EXPECT_FALSE(natural_less("img10.png", "img2.png"));
  EXPECT_TRUE(natural_less("img_9.bmp", "img_10.bmp"));
  EXPECT_TRUE(natural_less("a1b2", "a1b10"));
  EXPECT_TRUE(natural_less("frame_00.png", "frame_01.png"));
  EXPECT_TRUE(natural_less("img007", "img8"));
  // Equal numbers: fewer leading zeros first, so the order is strict.
  EXPECT_TRUE(natural_less("img7", "img007"));
  EXPECT_FALSE(natural_less("img007", "img7"));
  EXPECT_FALSE(natural_less("same", "same"));
  EXPECT_TRUE(natural_less("img", "img1"));
  EXPECT_TRUE(natural_less("cam0_5", "cam1_1"));
}

TEST(FringeFolder, ListsInNaturalOrderAndFilters) {
  TempDir dir;
  for (int k = 1; k <= 12; ++k) write_blank(dir / ("img" + std::to_string(k) + ".bmp"));
  write_blank(dir / "white.bmp");
  std::ofstream(dir / "notes.txt") << "not an image";
  FringeFolderOptions only;
  only.include = "img*";
  auto listed = list_fringe_images(dir.path(), only);
  ASSERT_TRUE(listed) << listed.status().message();
  ASSERT_EQ(listed->size(), 12u);
  EXPECT_EQ(names(*listed).front(), "img1.bmp");
  EXPECT_EQ(names(*listed)[1], "img2.bmp");
  EXPECT_EQ(names(*listed).back(), "img12.bmp");
  FringeFolderOptions without;
  without.exclude = "white*";
  auto folder = list_fringe_folder(dir.path(), 6, without);
  ASSERT_TRUE(folder) << folder.status().message();
  ASSERT_EQ(folder->frames.size(), 2u);
  EXPECT_EQ(names(folder->frames[1]).front(), "img7.bmp");
  EXPECT_EQ(folder->first_image[1], 6u);

  FringeFolderOptions none;
  none.include = "cam*";
  auto empty = list_fringe_images(dir.path(), none);
  ASSERT_FALSE(empty);
  EXPECT_TRUE(contains(empty.status().message(), "none of its 13 images passes"))
      << empty.status().message();
  FringeFolderOptions path_glob;
  path_glob.include = "sub/*.png";
  EXPECT_FALSE(list_fringe_images(dir.path(), path_glob));
}

TEST(FringeFolder, WrongCountNamesTheFilesAndTheStrayNamePattern) {
  TempDir dir;
  for (int k = 1; k <= 12; ++k) write_blank(dir / ("img_" + std::to_string(k) + ".png"));
  write_blank(dir / "white.png");
  auto r = list_fringe_folder(dir.path(), 6);
  ASSERT_FALSE(r);
  const std::string m = r.status().message();
  EXPECT_TRUE(contains(m, dir.path().string())) << m;
  EXPECT_TRUE(contains(m, "13 images (img_1.png .. white.png)")) << m;
  EXPECT_TRUE(contains(m, "not a multiple of the pattern set's 6 images")) << m;
  EXPECT_TRUE(contains(m, "img_#.png (12)")) << m;
  EXPECT_TRUE(contains(m, "white.png (1)")) << m;
  EXPECT_TRUE(contains(m, "--exclude")) << m;
  // One name pattern: the count itself is suspect.
  fs::remove(dir / "white.png");
  auto five = list_fringe_folder(dir.path(), 5);
  ASSERT_FALSE(five);
  EXPECT_TRUE(contains(five.status().message(), "check --pattern")) << five.status().message();
}

TEST(FringeFolder, SlidingWindowsFillEachSlotOnce) {
  TempDir dir;
  for (int k = 0; k < 7; ++k)
    write_blank(dir / ("s" + std::to_string(k) + ".png"), {4, 3}, CV_8U, k);
  FringeFolderOptions o;
  o.sliding = true;
  auto folder = list_fringe_folder(dir.path(), 3, o);
  ASSERT_TRUE(folder) << folder.status().message();
  ASSERT_EQ(folder->frames.size(), 5u);  // 7 - 3 + 1
  // Window 1 = images 1, 2, 3: image j in slot j mod 3 -> slots hold 3, 1, 2.
  EXPECT_EQ(names(folder->frames[1]), (std::vector<std::string>{"s3.png", "s1.png", "s2.png"}));
  EXPECT_EQ(folder->first_image[4], 4u);
  auto frame = read_fringe_frame(*folder, 2);  // images 2, 3, 4 -> slots 3, 4, 2
  ASSERT_TRUE(frame) << frame.status().message();
  EXPECT_EQ(frame->images[0].at<uint8_t>(0, 0), 3);
  EXPECT_EQ(frame->images[1].at<uint8_t>(0, 0), 4);
  EXPECT_EQ(frame->images[2].at<uint8_t>(0, 0), 2);
  auto too_few = list_fringe_folder(dir.path(), 8, o);
  ASSERT_FALSE(too_few);
  EXPECT_TRUE(contains(too_few.status().message(), "are fewer than")) << too_few.status().message();
}

TEST(FringeFolder, MixedSizesAndDepthsNameBothFiles) {
  TempDir dir;
  write_blank(dir / "a1.png", {8, 6});
  write_blank(dir / "a2.png", {8, 6});
  write_blank(dir / "a3.png", {10, 6});
  auto folder = list_fringe_folder(dir.path(), 3);
  ASSERT_TRUE(folder);
  auto r = read_fringe_frame(*folder, 0);
  ASSERT_FALSE(r);
  const std::string m = r.status().message();
  EXPECT_TRUE(contains(m, (dir / "a3.png").string() + ": 10x6 8-bit")) << m;
  EXPECT_TRUE(contains(m, (dir / "a1.png").string())) << m;
  EXPECT_TRUE(contains(m, "is 8x6 8-bit")) << m;
  write_blank(dir / "a3.png", {8, 6}, CV_16U);
  r = read_fringe_frame(*folder, 0);
  ASSERT_FALSE(r);
  EXPECT_TRUE(contains(r.status().message(), "8x6 16-bit")) << r.status().message();
}

TEST(PatternCandidates, ListTheSetsOfAnImageCount) {
  auto has = [](const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
  };
  const auto six = pattern_set_candidates(6);
  EXPECT_TRUE(has(six, "psp6-f<P>"));
  EXPECT_TRUE(has(six, "mf3-f<P>-f1"));
  EXPECT_TRUE(has(six, "gray3-psp3"));
  const auto three = pattern_set_candidates(3);
  EXPECT_TRUE(has(three, "psp3-f<P>"));
  EXPECT_TRUE(has(three, "zh-f<P>"));
  EXPECT_TRUE(pattern_set_candidates(2).empty());
  // Every concrete candidate (no placeholder) is a valid name with that image count.
  for (int n = 3; n <= 20; ++n)
    for (const std::string& name : pattern_set_candidates(n)) {
      if (name.find('<') != std::string::npos) continue;
      auto set = create_pattern_set(name);
      ASSERT_TRUE(set) << name << ": " << set.status().message();
      EXPECT_EQ((*set)->image_count(), n) << name;
    }
}

}  // namespace
}  // namespace gvkit::capture
