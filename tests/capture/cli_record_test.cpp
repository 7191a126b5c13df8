// `gvkit record` as a user runs it: a folder of images recorded and replayed bit-exact, with
// stats.json; bad sources, options and an existing recording give a message and exit 1.
#include <gtest/gtest.h>

#include "gvkit/core/image_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::run_gvkit;
using testing::TempDir;

using testing::contains;

cv::Mat image(int i) {
  cv::Mat m(20, 30, CV_16U);
  cv::RNG rng(static_cast<uint64_t>(i) + 5);
  rng.fill(m, cv::RNG::UNIFORM, 0, 65536);
  return m;
}

TEST(CliRecord, RecordsAFileSourceBitExact) {
  TempDir dir;
  std::filesystem::create_directories(dir / "in");
  for (int i = 0; i < 6; ++i)
    ASSERT_TRUE(
        write_image(dir / ("in/frame_00000" + std::to_string(i) + ".png"), image(i)).is_ok());
  const std::string out = (dir / "rec").string();
  auto r = run_gvkit("record --source file:" + (dir / "in").string() + " -o " + out +
                     " --frames 5 --no-status");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "recorded 5 frames")) << r.output;
  for (int i = 0; i < 5; ++i) {
    auto back = read_image(dir / ("rec/frame_00000" + std::to_string(i) + ".png"));
    ASSERT_TRUE(back.is_ok());
    EXPECT_EQ(cv::norm(*back, image(i), cv::NORM_INF), 0);
  }
  auto stats = read_json(dir / "rec" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["recorded"], 5);
  EXPECT_EQ((*stats)["dropped_by_queue"], 0);
  EXPECT_EQ((*stats)["options"]["policy"], "block");

  // Replaying the recording through the same command records the same frames again.
  auto again =
      run_gvkit("record --source file:" + out + " -o " + (dir / "rec2").string() + " --no-status");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  auto b = read_image(dir / "rec2/frame_000004.png");
  ASSERT_TRUE(b.is_ok());
  EXPECT_EQ(cv::norm(*b, image(4), cv::NORM_INF), 0);

  auto exists = run_gvkit("record --source file:" + (dir / "in").string() + " -o " + out);
  EXPECT_EQ(exists.exit_code, 1);
  EXPECT_TRUE(contains(exists.output, "already holds a recording")) << exists.output;
}

TEST(CliRecord, BadInputGivesAMessageAndExit1) {
  TempDir dir;
  const std::string out = " -o " + (dir / "x").string();
  auto device = run_gvkit("record --source v4l2:/dev/video-gvkit-none" + out);
  EXPECT_EQ(device.exit_code, 1);
  EXPECT_TRUE(contains(device.output, "/dev/video-gvkit-none: open: no such device"))
      << device.output;
  auto scheme = run_gvkit("record --source http://cam" + out);
  EXPECT_EQ(scheme.exit_code, 1);
  EXPECT_TRUE(contains(scheme.output, "unknown scheme 'http'")) << scheme.output;
  auto policy = run_gvkit("record --source file:/tmp --policy lifo" + out);
  EXPECT_EQ(policy.exit_code, 1);
  EXPECT_TRUE(contains(policy.output, "'lifo'")) << policy.output;
  auto size = run_gvkit("record --source file:/tmp --size 640" + out);
  EXPECT_EQ(size.exit_code, 1);
  EXPECT_TRUE(contains(size.output, "expected WxH")) << size.output;
  auto fps = run_gvkit("record --source file:/tmp --fps -3" + out);
  EXPECT_EQ(fps.exit_code, 1);
  EXPECT_TRUE(contains(fps.output, "fps")) << fps.output;
  auto libcamera = run_gvkit("record --source libcamera:0" + out);
  EXPECT_EQ(libcamera.exit_code, 1);
  EXPECT_FALSE(std::filesystem::exists(dir / "x"));  // nothing is created for a failed open
}

}  // namespace
}  // namespace gvkit
