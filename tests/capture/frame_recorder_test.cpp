// Crash-safe recording: round trip through file: replay is bit-exact; a full disk stops the
// recording cleanly and keeps what was written; a recording process killed with SIGKILL leaves
// a folder that opens and replays, missing at most the frame in flight.
#include "gvkit/capture/frame_recorder.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "gvkit/capture/file_frame_source.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
namespace fs = std::filesystem;
using testing::TempDir;

using testing::contains;

CameraFrame make_frame(int64_t i, int depth = CV_16U) {
  CameraFrame f;
  f.image = cv::Mat(24, 40, depth);
  cv::RNG rng(static_cast<uint64_t>(i) + 1);
  rng.fill(f.image, cv::RNG::UNIFORM, 0, depth == CV_16U ? 65536 : 256);
  f.sequence = 100 + 2 * i;  // gaps on purpose: recorded as they came
  f.timestamp = Timestamp(1'000'000'000 + i * 33'333'333);
  return f;
}

FrameRecorderOptions quiet_options() {
  FrameRecorderOptions o;
  o.min_free_bytes = 0;
  o.source_description = "synthetic:test";
  return o;
}

std::vector<CameraFrame> replay(const fs::path& dir, int64_t* dropped = nullptr) {
  auto source = open_file_source(dir.string(), {});
  EXPECT_TRUE(source.is_ok()) << source.status().message();
  std::vector<CameraFrame> frames;
  if (!source.is_ok()) return frames;
  for (;;) {
    auto f = (*source)->next();
    EXPECT_TRUE(f.is_ok()) << f.status().message();
    if (!f.is_ok() || !f->has_value()) break;
    frames.push_back(std::move(**f));
  }
  if (dropped) *dropped = (*source)->counters().dropped;
  return frames;
}

TEST(FrameRecorder, RecordingReplaysBitExact) {
  for (int depth : {CV_8U, CV_16U}) {
    TempDir dir;
    auto recorder = FrameRecorder::create(dir / "take1", quiet_options());
    ASSERT_TRUE(recorder.is_ok()) << recorder.status().message();
    for (int64_t i = 0; i < 5; ++i) ASSERT_TRUE((*recorder)->append(make_frame(i, depth)).is_ok());
    FrameSourceCounters counters;
    counters.dropped = 3;
    (*recorder)->set_source_counters(counters);
    ASSERT_TRUE((*recorder)->close().is_ok());

    int64_t dropped = -1;
    const std::vector<CameraFrame> back = replay(dir / "take1", &dropped);
    ASSERT_EQ(back.size(), 5u);
    EXPECT_EQ(dropped, 3);
    for (int64_t i = 0; i < 5; ++i) {
      const CameraFrame expected = make_frame(i, depth);
      const CameraFrame& got = back[static_cast<size_t>(i)];
      EXPECT_EQ(got.image.type(), expected.image.type());
      EXPECT_EQ(cv::norm(got.image, expected.image, cv::NORM_INF), 0);
      EXPECT_EQ(got.sequence, expected.sequence);
      EXPECT_EQ(got.timestamp, expected.timestamp);
    }
    auto index = read_json(dir / "take1" / "frames.json");
    ASSERT_TRUE(index.is_ok());
    EXPECT_EQ((*index)["complete"], true);
    EXPECT_EQ((*index)["bits"], depth == CV_16U ? 16 : 8);
  }
}

TEST(FrameRecorder, RefusesToOverwriteAndBadFrames) {
  TempDir dir;
  {
    auto first = FrameRecorder::create(dir.path(), quiet_options());
    ASSERT_TRUE(first.is_ok());
    ASSERT_TRUE((*first)->append(make_frame(0)).is_ok());
    CameraFrame other = make_frame(1);
    other.image = cv::Mat(8, 8, CV_16U, cv::Scalar(1));
    EXPECT_TRUE(contains((*first)->append(other).message(), "differs from the recording's first"));
    CameraFrame colour = make_frame(2);
    colour.image = cv::Mat(24, 40, CV_8UC3);
    EXPECT_FALSE((*first)->append(colour).is_ok());
  }
  auto second = FrameRecorder::create(dir.path(), quiet_options());
  ASSERT_FALSE(second.is_ok());
  EXPECT_TRUE(contains(second.status().message(), "already holds a recording"));
  EXPECT_EQ(replay(dir.path()).size(), 1u);  // the bad frames were never recorded
}

TEST(FrameRecorder, AFullDiskStopsCleanlyAndKeepsWhatIsWritten) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  TempDir dir;
  auto recorder = FrameRecorder::create(dir.path(), quiet_options());
  ASSERT_TRUE(recorder.is_ok());
  for (int64_t i = 0; i < 3; ++i) ASSERT_TRUE((*recorder)->append(make_frame(i)).is_ok());
  // The next frame's temporary file is a link to /dev/full: its write fails with ENOSPC, as on a
  // full disk.
  const fs::path temp = dir / ("frame_000003.png.tmp-" + std::to_string(::getpid()) + ".png");
  fs::create_symlink("/dev/full", temp);
  const Status full = (*recorder)->append(make_frame(3));
  ASSERT_FALSE(full.is_ok());
  EXPECT_EQ(full.code(), StatusCode::kIoError);
  EXPECT_TRUE(contains(full.message(), "recording stopped after 3 frames (all kept)"))
      << full.message();
  EXPECT_TRUE(contains(full.message(), "No space left on device")) << full.message();
  EXPECT_FALSE((*recorder)->append(make_frame(4)).is_ok());  // stays stopped
  EXPECT_FALSE(fs::exists(temp));
  const std::vector<CameraFrame> back = replay(dir.path());
  ASSERT_EQ(back.size(), 3u);
  EXPECT_EQ(cv::norm(back[2].image, make_frame(2).image, cv::NORM_INF), 0);
  auto index = read_json(dir / "frames.json");
  ASSERT_TRUE(index.is_ok());
  EXPECT_TRUE(contains((*index)["stop_reason"].get<std::string>(), "No space left"));

  // A nearly full disk (less free than asked for) stops before writing anything.
  TempDir other;
  FrameRecorderOptions o = quiet_options();
  o.min_free_bytes = int64_t{1} << 60;
  auto cautious = FrameRecorder::create(other.path(), o);
  ASSERT_TRUE(cautious.is_ok());
  const Status nearly = (*cautious)->append(make_frame(0));
  EXPECT_TRUE(contains(nearly.message(), "the disk is nearly full")) << nearly.message();
}

TEST(FrameRecorder, SigkillLosesAtMostTheFrameInFlight) {
  TempDir dir;
  const fs::path folder = dir / "crash";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    auto recorder = FrameRecorder::create(folder, quiet_options());
    if (!recorder.is_ok()) ::_exit(3);
    for (int64_t i = 0; i < 100000; ++i)
      if (!(*recorder)->append(make_frame(i)).is_ok()) ::_exit(4);
    ::_exit(0);
  }
  // Kill it once the index lists at least 15 frames, at whatever step it is in.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  for (;;) {
    auto index = read_json(folder / "frames.json");
    if (index.is_ok() && (*index)["frames"].size() >= 15) break;
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the recorder made no progress";
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);

  auto index = read_json(folder / "frames.json");
  ASSERT_TRUE(index.is_ok()) << index.status().message();
  EXPECT_EQ((*index)["complete"], false);
  const size_t listed = (*index)["frames"].size();
  const std::vector<CameraFrame> back = replay(folder);
  ASSERT_EQ(back.size(), listed);
  for (size_t i = 0; i < back.size(); ++i)
    ASSERT_EQ(cv::norm(back[i].image, make_frame(static_cast<int64_t>(i)).image, cv::NORM_INF), 0)
        << "frame " << i;
  auto files = list_frame_files(folder, ".png");
  ASSERT_TRUE(files.is_ok());
  EXPECT_LE(files->size(), listed + 1);  // at most the frame in flight is unlisted
}

}  // namespace
}  // namespace gvkit
