#include "gvkit/player/frame_sequence.hpp"

#include <fstream>

#include <gtest/gtest.h>

#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/player/exr_folder_sequence.hpp"
#include "player_test_data.hpp"
#include "support/test_support.hpp"

namespace gvkit::player {
namespace {

using gvkit::testing::TempDir;

TEST(FrameSequence, OpensAnExrFolderAndReadsEveryFrame) {
  TempDir tmp;
  testing::write_face_like_sequence(tmp.path(), 3, 24);
  auto seq = FrameSequence::create(tmp.path());
  ASSERT_TRUE(seq.is_ok()) << seq.status().message();
  EXPECT_EQ((*seq)->frame_count(), 3);
  EXPECT_DOUBLE_EQ((*seq)->fps(), 30.0);
  EXPECT_NE((*seq)->name().find("3 frames"), std::string::npos);
  for (int i = 0; i < 3; ++i) {
    auto frame = (*seq)->frame(i);
    ASSERT_TRUE(frame.is_ok()) << frame.status().message();
    EXPECT_EQ(frame->index, i);
    EXPECT_EQ(frame->timestamp.count(), static_cast<int64_t>(i * 1e9 / 30.0));
    const GeometryImage expected = testing::make_face_like_image(24, i);
    EXPECT_EQ(cv::norm(frame->xyz_mm, expected.xyz_mm, cv::NORM_INF, expected.domain_mask), 0.0);
    EXPECT_EQ(cv::countNonZero(frame->domain_mask != expected.domain_mask), 0);
    ASSERT_TRUE((*seq)->frame_bits(i).has_value());
    EXPECT_GT(*(*seq)->frame_bits(i), 0);
  }
}

TEST(FrameSequence, FpsComesFromStatsJson) {
  TempDir tmp;
  testing::write_face_like_sequence(tmp.path(), 1, 8);
  ASSERT_TRUE(write_json(tmp / "stats.json", {{"options", {{"fps", 60}}}}).is_ok());
  auto seq = FrameSequence::create(tmp.path());
  ASSERT_TRUE(seq.is_ok());
  EXPECT_DOUBLE_EQ((*seq)->fps(), 60.0);
}

TEST(FrameSequence, CorruptFrameFailsAloneAndNamesItsFile) {
  TempDir tmp;
  testing::write_face_like_sequence(tmp.path(), 3, 16);
  {  // Truncate frame 1 to half its size.
    const auto path = frame_path(tmp.path(), 1, ".exr");
    const auto size = std::filesystem::file_size(path);
    std::filesystem::resize_file(path, size / 2);
  }
  auto seq = FrameSequence::create(tmp.path());
  ASSERT_TRUE(seq.is_ok()) << seq.status().message();
  EXPECT_TRUE((*seq)->frame(0).is_ok());
  auto bad = (*seq)->frame(1);
  ASSERT_FALSE(bad.is_ok());
  EXPECT_NE(bad.status().message().find("frame_000001.exr"), std::string::npos)
      << bad.status().message();
  EXPECT_TRUE((*seq)->frame(2).is_ok());
}

TEST(FrameSequence, FolderOfRangeScansPlaysWithValidAsMask) {
  TempDir tmp;
  RangeScan scan;
  scan.xyz_mm = cv::Mat(6, 5, CV_32FC3, cv::Scalar(1, 2, 600));
  scan.valid = cv::Mat(6, 5, CV_8U, cv::Scalar(255));
  scan.texture = cv::Mat(6, 5, CV_32F, cv::Scalar(0.25));
  scan.quality = cv::Mat(6, 5, CV_32F, cv::Scalar(0.9));
  scan.valid.at<uint8_t>(2, 2) = 0;
  scan.xyz_mm.at<cv::Vec3f>(2, 2) = cv::Vec3f(NAN, NAN, NAN);
  ASSERT_TRUE(write_range_scan_exr(frame_path(tmp.path(), 0, ".exr"), scan).is_ok());
  auto seq = ExrFolderSequence::open(tmp.path());
  ASSERT_TRUE(seq.is_ok()) << seq.status().message();
  EXPECT_EQ((*seq)->kind(), ExrFolderSequence::Kind::kRangeScan);
  auto frame = (*seq)->frame(0);
  ASSERT_TRUE(frame.is_ok()) << frame.status().message();
  EXPECT_EQ(frame->domain_mask.at<uint8_t>(2, 2), 0);
  EXPECT_EQ(cv::countNonZero(frame->domain_mask), 29);
  EXPECT_FLOAT_EQ(frame->texture.at<float>(0, 0), 0.25f);
}

TEST(FrameSequence, BadPathsAreRejectedWithTheirName) {
  TempDir tmp;
  auto missing = FrameSequence::create(tmp / "nope");
  ASSERT_FALSE(missing.is_ok());
  EXPECT_NE(missing.status().message().find("nope"), std::string::npos);
  auto empty = FrameSequence::create(tmp.path());
  ASSERT_FALSE(empty.is_ok());
  EXPECT_NE(empty.status().message().find("no frame_NNNNNN.exr"), std::string::npos);
  std::ofstream(tmp / "clip.mkv") << "x";
  auto unknown = FrameSequence::create(tmp / "clip.mkv");
  ASSERT_FALSE(unknown.is_ok());
  EXPECT_EQ(unknown.status().code(), StatusCode::kUnsupported);
  // A folder whose only frame is garbage.
  TempDir garbage;
  std::ofstream(frame_path(garbage.path(), 0, ".exr")) << "not an exr";
  auto bad = FrameSequence::create(garbage.path());
  ASSERT_FALSE(bad.is_ok());
  EXPECT_NE(bad.status().message().find("no readable frame"), std::string::npos);
}

}  // namespace
}  // namespace gvkit::player
