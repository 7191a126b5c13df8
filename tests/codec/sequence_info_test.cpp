// SequenceInfoBuilder (a video's quantization box and mask from frames given one at a time) against
// make_sequence_info, its rejections naming the frame, and check_frame_fits (a frame read again
// after the box was made).
#include <gtest/gtest.h>

#include "geometry_video_material.hpp"
#include "gvkit/codec/sequence_info.hpp"

namespace gvkit::codec {
namespace {

std::vector<GeometryImage> video(int frames = 4) {
  testing::GeometryVideoOptions o;
  o.size = 24;
  o.frames = frames;
  return testing::make_moving_analytic_video(o.size, o.frames);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(SequenceInfoBuilder, FrameByFrameEqualsTheWholeVideo) {
  const auto frames = video();
  const SequenceInfo whole = make_sequence_info(frames, 12, 25.0).value();
  SequenceInfoBuilder builder(12, 25.0);
  for (const GeometryImage& f : frames) ASSERT_TRUE(builder.add(f).is_ok());
  EXPECT_EQ(builder.frames(), 4);
  const SequenceInfo built = builder.finish().value();
  EXPECT_EQ(built.width, whole.width);
  EXPECT_EQ(built.height, whole.height);
  EXPECT_EQ(built.bit_depth, 12);
  EXPECT_EQ(built.fps, 25.0);
  EXPECT_EQ(built.has_texture, whole.has_texture);
  EXPECT_EQ(cv::countNonZero(built.domain_mask != whole.domain_mask), 0);
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(built.box_min_mm[a], whole.box_min_mm[a]);
    EXPECT_EQ(built.box_max_mm[a], whole.box_max_mm[a]);
  }
  // The box grows with the frames: the first frame alone gives a smaller or equal one, and a
  // later frame's pixel sets a bound.
  SequenceInfoBuilder first(12, 25.0);
  ASSERT_TRUE(first.add(frames[0]).is_ok());
  const SequenceInfo one = first.finish().value();
  bool smaller = false;
  for (int a = 0; a < 3; ++a) {
    EXPECT_GE(one.box_min_mm[a], whole.box_min_mm[a]);
    EXPECT_LE(one.box_max_mm[a], whole.box_max_mm[a]);
    smaller = smaller || one.box_min_mm[a] > whole.box_min_mm[a] ||
              one.box_max_mm[a] < whole.box_max_mm[a];
  }
  EXPECT_TRUE(smaller);
}

TEST(SequenceInfoBuilder, RejectsFramesThatDoNotMatchFrameZeroNamingThem) {
  const auto frames = video(3);
  const auto fails_at_frame_1 = [&](GeometryImage bad, const std::string& message) {
    SequenceInfoBuilder builder(16, 30.0);
    ASSERT_TRUE(builder.add(frames[0]).is_ok());
    const Status s = builder.add(bad);
    EXPECT_FALSE(s.is_ok());
    EXPECT_TRUE(contains(s.message(), "frame 1: " + message)) << s.message();
    // Nothing more is taken, and there is no info.
    EXPECT_FALSE(builder.add(frames[2]).is_ok());
    EXPECT_FALSE(builder.finish().is_ok());
    // make_sequence_info says the same.
    const Result<SequenceInfo> whole = make_sequence_info({frames[0], bad, frames[2]}, 16, 30.0);
    ASSERT_FALSE(whole.is_ok());
    EXPECT_EQ(whole.status().message(), s.message());
  };
  GeometryImage other_size;
  other_size.xyz_mm = frames[1].xyz_mm(cv::Rect(4, 4, 16, 16)).clone();
  other_size.domain_mask = frames[1].domain_mask(cv::Rect(4, 4, 16, 16)).clone();
  fails_at_frame_1(other_size, "size differs from frame 0");
  GeometryImage other_mask = frames[1];
  other_mask.domain_mask = frames[1].domain_mask.clone();
  other_mask.domain_mask.at<uint8_t>(12, 12) ^= 255;
  fails_at_frame_1(other_mask, "domain mask differs from frame 0");
  GeometryImage textured = frames[1];
  textured.texture = cv::Mat(frames[1].xyz_mm.size(), CV_32F, cv::Scalar(0.5));
  fails_at_frame_1(textured, "texture present in some frames only");

  SequenceInfoBuilder empty(16, 30.0);
  EXPECT_FALSE(empty.finish().is_ok());
  GeometryImage no_domain = frames[0];
  no_domain.domain_mask = cv::Mat::zeros(frames[0].xyz_mm.size(), CV_8U);
  SequenceInfoBuilder blank(16, 30.0);
  const Status s = blank.add(no_domain);
  EXPECT_TRUE(contains(s.message(), "frame 0: no domain pixel")) << s.message();
}

TEST(CheckFrameFits, AcceptsTheVideosFramesAndRejectsAChangedOne) {
  const auto frames = video();
  const SequenceInfo info = make_sequence_info(frames, 16, 30.0).value();
  for (const GeometryImage& f : frames) EXPECT_TRUE(check_frame_fits(info, f).is_ok());
  // A domain pixel moved out of the box (as a file rewritten between the two readings).
  GeometryImage moved = frames[2];
  moved.xyz_mm = frames[2].xyz_mm.clone();
  int x = -1, y = -1;
  for (int r = 0; r < moved.xyz_mm.rows && x < 0; ++r)
    for (int c = 0; c < moved.xyz_mm.cols && x < 0; ++c)
      if (moved.domain_mask.at<uint8_t>(r, c)) x = c, y = r;
  ASSERT_GE(x, 0);
  moved.xyz_mm.at<cv::Vec3f>(y, x)[2] = static_cast<float>(info.box_max_mm[2] + 1.0);
  Status s = check_frame_fits(info, moved);
  EXPECT_TRUE(contains(s.message(), "outside the quantization box")) << s.message();
  // Outside the domain, values do not matter.
  GeometryImage outside = frames[2];
  outside.xyz_mm = frames[2].xyz_mm.clone();
  for (int r = 0; r < outside.xyz_mm.rows; ++r)
    for (int c = 0; c < outside.xyz_mm.cols; ++c)
      if (!outside.domain_mask.at<uint8_t>(r, c)) outside.xyz_mm.at<cv::Vec3f>(r, c) = {1e6, 0, 0};
  EXPECT_TRUE(check_frame_fits(info, outside).is_ok());
  GeometryImage other_mask = frames[1];
  other_mask.domain_mask = frames[1].domain_mask.clone();
  other_mask.domain_mask.at<uint8_t>(0, 0) ^= 255;
  s = check_frame_fits(info, other_mask);
  EXPECT_FALSE(s.is_ok());
  GeometryImage textured = frames[1];
  textured.texture = cv::Mat(frames[1].xyz_mm.size(), CV_32F, cv::Scalar(0.5));
  s = check_frame_fits(info, textured);
  EXPECT_TRUE(contains(s.message(), "texture not in the sequence")) << s.message();
}

}  // namespace
}  // namespace gvkit::codec
