#include "gvkit/core/image_io.hpp"

#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::TempDir;

TEST(ImageIo, PngRoundTripsAt8And16Bits) {
  TempDir dir;
  for (int type : {CV_8U, CV_16U, CV_8UC3}) {
    cv::Mat image(31, 17, type);
    cv::randu(image, 0, type == CV_16U ? 65535 : 255);
    const auto path = dir / ("im" + std::to_string(type) + ".png");
    ASSERT_TRUE(write_image(path, image).is_ok());
    auto back = read_image(path);
    ASSERT_TRUE(back.is_ok()) << back.status().message();
    EXPECT_EQ(back->type(), type);
    EXPECT_EQ(cv::norm(*back, image, cv::NORM_INF), 0.0);
  }
}

TEST(ImageIo, GreyConversionAndDepthChecks) {
  TempDir dir;
  cv::Mat colour(8, 8, CV_8UC3, cv::Scalar(10, 20, 30));
  ASSERT_TRUE(write_image(dir / "c.png", colour).is_ok());
  auto grey = read_image(dir / "c.png", true);
  ASSERT_TRUE(grey.is_ok());
  EXPECT_EQ(grey->channels(), 1);
  auto wrong_depth = read_image(dir / "c.png", false, ImageDepth::k16);
  EXPECT_EQ(wrong_depth.status().code(), StatusCode::kUnsupported);
}

TEST(ImageIo, BadFilesAreRejectedWithTheirName) {
  TempDir dir;
  EXPECT_EQ(read_image(dir / "none.png").status().code(), StatusCode::kNotFound);
  cv::Mat image(64, 64, CV_16U);
  cv::randu(image, 0, 65535);
  ASSERT_TRUE(write_image(dir / "full.png", image).is_ok());
  const std::string bytes = *read_file(dir / "full.png");
  ASSERT_TRUE(write_file_atomically(dir / "cut.png", bytes.substr(0, bytes.size() / 3)).is_ok());
  auto cut = read_image(dir / "cut.png");
  ASSERT_FALSE(cut.is_ok());
  EXPECT_NE(cut.status().message().find("cut.png"), std::string::npos);
  EXPECT_FALSE(write_image(dir / "f.png", cv::Mat(4, 4, CV_32F)).is_ok());
  EXPECT_FALSE(std::filesystem::exists(dir / "f.png"));
}

}  // namespace
}  // namespace gvkit
