// Session folder: write (append-only, out of order, atomically listed) and read back.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "gvkit/capture/session_reader.hpp"
#include "gvkit/capture/session_writer.hpp"
#include "gvkit/capture/synthetic_rig.hpp"
#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"

namespace gvkit::capture {
namespace {
using testing::TempDir;

SessionInfo small_info(int bit_depth) {
  SessionInfo info;
  info.pattern = "psp3-f16";
  info.images_per_frame = 3;
  info.fps = 25;
  info.width = 32;
  info.height = 24;
  info.bit_depth = bit_depth;
  info.source = {{"kind", "test"}};
  return info;
}

FringeSet random_frame(int64_t index, int depth, uint64_t seed) {
  FringeSet f;
  f.index = index;
  f.timestamp = Timestamp(index * 40'000'000);
  cv::RNG rng(seed);
  for (int k = 0; k < 3; ++k) {
    cv::Mat im(24, 32, depth);
    rng.fill(im, cv::RNG::UNIFORM, 0, depth == CV_8U ? 256 : 65536);
    f.images.push_back(im);
  }
  return f;
}

TEST(Session, RoundTripOutOfOrder) {
  for (int bits : {8, 12}) {
    TempDir dir;
    const int depth = bits == 8 ? CV_8U : CV_16U;
    const Calibration calibration = synthetic_calibration();
    auto writer = SessionWriter::create(dir.path() / "s", small_info(bits), calibration);
    ASSERT_TRUE(writer) << writer.status().message();
    for (int64_t i : {2, 0, 1}) ASSERT_TRUE((*writer)->append(random_frame(i, depth, i + 10)));
    ASSERT_TRUE((*writer)->add_dropped(4));

    auto reader = SessionReader::open(dir.path() / "s");
    ASSERT_TRUE(reader) << reader.status().message();
    EXPECT_EQ(reader->frame_count(), 3u);
    EXPECT_EQ(reader->info().dropped_frames, 4);
    EXPECT_EQ(reader->info().pattern, "psp3-f16");
    EXPECT_EQ(reader->info().bit_depth, bits);
    EXPECT_DOUBLE_EQ(reader->info().fps, 25);
    EXPECT_EQ(reader->info().source["kind"], "test");
    EXPECT_EQ(reader->info().depth_prior_mm, 0.0);  // not recorded
    EXPECT_NEAR(reader->calibration().camera_K(0, 0), calibration.camera_K(0, 0), 1e-9);
    for (size_t i = 0; i < 3; ++i) {
      auto f = reader->read_frame(i);
      ASSERT_TRUE(f) << f.status().message();
      EXPECT_EQ(f->index, static_cast<int64_t>(i));
      EXPECT_EQ(f->timestamp.count(), static_cast<int64_t>(i) * 40'000'000);
      const FringeSet expected = random_frame(static_cast<int64_t>(i), depth, i + 10);
      for (int k = 0; k < 3; ++k) EXPECT_EQ(cv::norm(f->images[k], expected.images[k]), 0.0);
    }
    EXPECT_FALSE(reader->ground_truth_path(0));
  }
}

TEST(Session, DepthPriorRoundTripsAndMustBeADepth) {
  SessionInfo info = small_info(8);
  info.depth_prior_mm = 812.5;
  auto back = SessionInfo::from_json(info.to_json(), "session.json");
  ASSERT_TRUE(back) << back.status().message();
  EXPECT_EQ(back->depth_prior_mm, 812.5);
  nlohmann::json bad = info.to_json();
  bad["depth_prior_mm"] = -5.0;
  auto rejected = SessionInfo::from_json(bad, "session.json");
  ASSERT_FALSE(rejected);
  EXPECT_NE(rejected.status().message().find("depth_prior_mm"), std::string::npos);
}

TEST(Session, WriterRejectsBadFramesAndExistingSessions) {
  TempDir dir;
  auto writer = SessionWriter::create(dir.path(), small_info(8), synthetic_calibration());
  ASSERT_TRUE(writer);
  FringeSet f = random_frame(5, CV_8U, 1);
  f.images.pop_back();
  Status s = (*writer)->append(f);
  EXPECT_FALSE(s);
  EXPECT_NE(s.message().find("frame 5"), std::string::npos) << s.message();
  EXPECT_FALSE((*writer)->append(random_frame(6, CV_16U, 1)));  // 16-bit into an 8-bit session
  EXPECT_FALSE(SessionWriter::create(dir.path(), small_info(8), synthetic_calibration()));
}

TEST(Session, AFailedImageWriteFailsTheFrameAndLeavesItUnlisted) {
  // The images of a set are written concurrently; a failure of any one (here the second: its
  // name is taken by a folder) fails append with that file's name and the set is not listed.
  TempDir dir;
  auto writer = SessionWriter::create(dir.path(), small_info(8), synthetic_calibration());
  ASSERT_TRUE(writer) << writer.status().message();
  ASSERT_TRUE((*writer)->append(random_frame(0, CV_8U, 1)));
  std::filesystem::create_directories(dir.path() / "frames" / "frame_000001_k1.png" / "x");
  Status s = (*writer)->append(random_frame(1, CV_8U, 2));
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find("frame_000001_k1.png"), std::string::npos) << s.message();
  ASSERT_TRUE((*writer)->append(random_frame(2, CV_8U, 3)));
  auto reader = SessionReader::open(dir.path());
  ASSERT_TRUE(reader) << reader.status().message();
  ASSERT_EQ(reader->frame_count(), 2u);
  EXPECT_EQ(reader->info().frames[0].index, 0);
  EXPECT_EQ(reader->info().frames[1].index, 2);
}

TEST(Session, ReaderRejectsBrokenFolders) {
  TempDir dir;
  EXPECT_FALSE(SessionReader::open(dir.path()));  // no session.json
  ASSERT_TRUE(write_json(dir / "session.json", {{"format", "something-else"}, {"version", 1}}));
  auto r = SessionReader::open(dir.path());
  ASSERT_FALSE(r);
  EXPECT_NE(r.status().message().find("session.json"), std::string::npos) << r.status().message();

  TempDir dir2;
  auto writer = SessionWriter::create(dir2.path(), small_info(8), synthetic_calibration());
  ASSERT_TRUE(writer);
  ASSERT_TRUE((*writer)->append(random_frame(0, CV_8U, 1)));
  std::filesystem::remove(dir2.path() / "frames" / "frame_000000_k1.png");
  auto reader = SessionReader::open(dir2.path());
  ASSERT_TRUE(reader);
  auto frame = reader->read_frame(0);
  ASSERT_FALSE(frame);
  EXPECT_NE(frame.status().message().find("frame_000000_k1.png"), std::string::npos);
  auto json = read_json(dir2 / "session.json");
  ASSERT_TRUE(json);
  (*json)["version"] = 99;
  ASSERT_TRUE(write_json(dir2 / "session.json", *json));
  auto v = SessionReader::open(dir2.path());
  ASSERT_FALSE(v);
  EXPECT_NE(v.status().message().find("version 99"), std::string::npos) << v.status().message();
}

}  // namespace
}  // namespace gvkit::capture
