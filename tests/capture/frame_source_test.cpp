// FrameSource::create dispatch, options checks, the callback (synthetic) source and file replay.
#include "gvkit/capture/frame_source.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include <opencv2/videoio.hpp>

#include "gvkit/capture/callback_frame_source.hpp"
#include "gvkit/capture/pattern_sync.hpp"
#include "gvkit/capture/session_writer.hpp"
#include "gvkit/capture/synthetic_rig.hpp"
#include "gvkit/core/image_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::TempDir;

using testing::contains;

cv::Mat ramp(int index, int depth = CV_8U) {
  cv::Mat image(24, 32, depth);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const int v = (x + 3 * y + 7 * index) % 251;
      if (depth == CV_8U)
        image.at<uint8_t>(y, x) = static_cast<uint8_t>(v);
      else
        image.at<uint16_t>(y, x) = static_cast<uint16_t>(v * 257 + index);
    }
  return image;
}

TEST(FrameSourceOptions, CheckNamesTheBadField) {
  EXPECT_TRUE(FrameSourceOptions{}.check().is_ok());
  FrameSourceOptions o;
  o.fps = -1;
  EXPECT_TRUE(contains(o.check().message(), "fps")) << o.check().message();
  o = {};
  o.width = 640;
  EXPECT_TRUE(contains(o.check().message(), "width and height"));
  o = {};
  o.pixel_format = "RGB3";
  EXPECT_TRUE(contains(o.check().message(), "'RGB3' is not one of"));
  o = {};
  o.buffer_count = 1;
  EXPECT_FALSE(o.check().is_ok());
  o = {};
  o.paced = true;
  EXPECT_TRUE(contains(o.check().message(), "paced"));
}

TEST(FrameSource, CreateRejectsBadUris) {
  FrameSourceOptions o;
  auto none = FrameSource::create("video0", o);
  ASSERT_FALSE(none.is_ok());
  EXPECT_TRUE(contains(none.status().message(), "expected v4l2:/dev/videoN"));
  auto unknown = FrameSource::create("rtsp://cam", o);
  ASSERT_FALSE(unknown.is_ok());
  EXPECT_TRUE(contains(unknown.status().message(), "unknown scheme 'rtsp'"));
  auto synthetic = FrameSource::create("synthetic:", o);
  ASSERT_FALSE(synthetic.is_ok());
  EXPECT_EQ(synthetic.status().code(), StatusCode::kUnsupported);
  EXPECT_TRUE(contains(synthetic.status().message(), "synthetic_generator"));
  auto missing = FrameSource::create("file:/no/such/folder", o);
  ASSERT_FALSE(missing.is_ok());
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  auto v4l2 = FrameSource::create("v4l2:/dev/video-gvkit-none", o);
  ASSERT_FALSE(v4l2.is_ok());
  EXPECT_EQ(v4l2.status().code(), StatusCode::kNotFound) << v4l2.status().message();
  EXPECT_TRUE(contains(v4l2.status().message(), "/dev/video-gvkit-none: open: no such device"));
  o.fps = -5;
  EXPECT_EQ(FrameSource::create("synthetic:", o).status().code(), StatusCode::kInvalidArgument);
}

TEST(CallbackSource, DeliversGeneratedFramesWithSyntheticClock) {
  FrameSourceOptions o;
  o.fps = 50;
  o.frame_count = 5;
  o.synthetic_generator = [](int64_t i) -> Result<cv::Mat> { return ramp(static_cast<int>(i)); };
  auto source = FrameSource::create("synthetic:", o);
  ASSERT_TRUE(source.is_ok()) << source.status().message();
  for (int i = 0; i < 5; ++i) {
    auto frame = (*source)->next();
    ASSERT_TRUE(frame.is_ok());
    ASSERT_TRUE(frame->has_value());
    EXPECT_EQ((*frame)->sequence, i);
    EXPECT_EQ((*frame)->timestamp.count(), i * 20'000'000);
    EXPECT_EQ(cv::norm((*frame)->image, ramp(i), cv::NORM_INF), 0);
  }
  auto end = (*source)->next();
  ASSERT_TRUE(end.is_ok());
  EXPECT_FALSE(end->has_value());
  EXPECT_EQ((*source)->counters().frames, 5);
  EXPECT_TRUE(contains((*source)->describe(), "synthetic:"));
}

TEST(CallbackSource, PacedRunsInRealTimeWithMonotonicTimestamps) {
  FrameSourceOptions o;
  o.fps = 200;
  o.paced = true;
  o.frame_count = 6;
  auto source = make_callback_source([](int64_t i) -> Result<cv::Mat> { return ramp(0); }, o);
  const auto start = std::chrono::steady_clock::now();
  Timestamp last{0};
  int n = 0;
  for (;;) {
    auto frame = source->next();
    ASSERT_TRUE(frame.is_ok());
    if (!frame->has_value()) break;
    EXPECT_GT((*frame)->timestamp, last);
    last = (*frame)->timestamp;
    ++n;
  }
  EXPECT_EQ(n, 6);
  // Frame 5 is due 25 ms after frame 0: pacing must have waited at least that long.
  EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(24));
}

TEST(CallbackSource, GeneratorFailuresAndBadImagesEndTheStreamWithAStatus) {
  FrameSourceOptions o;
  auto failing = make_callback_source(
      [](int64_t i) -> Result<cv::Mat> {
        if (i == 2) return io_error("renderer lost its context");
        return ramp(0);
      },
      o, "synthetic:face");
  ASSERT_TRUE(failing->next().is_ok());
  ASSERT_TRUE(failing->next().is_ok());
  auto third = failing->next();
  ASSERT_FALSE(third.is_ok());
  EXPECT_EQ(third.status().message(), "synthetic:face: frame 2: renderer lost its context");
  EXPECT_FALSE(failing->next().is_ok());  // stays failed

  auto colour = make_callback_source(
      [](int64_t) -> Result<cv::Mat> { return cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(1)); }, o);
  auto bad = colour->next();
  ASSERT_FALSE(bad.is_ok());
  EXPECT_TRUE(contains(bad.status().message(), "3-channel")) << bad.status().message();

  auto finite = make_callback_source(
      [](int64_t i) -> Result<cv::Mat> { return i < 3 ? ramp(0) : cv::Mat(); }, o);
  int n = 0;
  while (true) {
    auto f = finite->next();
    ASSERT_TRUE(f.is_ok());
    if (!f->has_value()) break;
    ++n;
  }
  EXPECT_EQ(n, 3);
}

TEST(FileSource, ReplaysAnImageFolderBitExactIn8And16Bit) {
  for (int depth : {CV_8U, CV_16U}) {
    TempDir dir;
    for (int i = 0; i < 4; ++i)
      ASSERT_TRUE(
          write_image(dir / ("frame_00000" + std::to_string(i) + ".png"), ramp(i, depth)).is_ok());
    FrameSourceOptions o;
    o.fps = 10;
    auto source = FrameSource::create("file:" + dir.path().string(), o);
    ASSERT_TRUE(source.is_ok()) << source.status().message();
    for (int i = 0; i < 4; ++i) {
      auto frame = (*source)->next();
      ASSERT_TRUE(frame.is_ok() && frame->has_value());
      EXPECT_EQ((*frame)->image.depth(), depth);
      EXPECT_EQ(cv::norm((*frame)->image, ramp(i, depth), cv::NORM_INF), 0);
      EXPECT_EQ((*frame)->sequence, i);
      EXPECT_EQ((*frame)->timestamp.count(), i * 100'000'000);
    }
    auto end = (*source)->next();
    ASSERT_TRUE(end.is_ok());
    EXPECT_FALSE(end->has_value());
    EXPECT_TRUE(contains((*source)->describe(), "4 images"));
  }
}

TEST(FileSource, LoopsAndRejectsBadFolders) {
  TempDir dir;
  for (int i = 0; i < 2; ++i)
    ASSERT_TRUE(write_image(dir / ("img" + std::to_string(i) + ".png"), ramp(i)).is_ok());
  FrameSourceOptions o;
  o.loop = true;
  auto source = FrameSource::create("file:" + dir.path().string(), o);
  ASSERT_TRUE(source.is_ok());
  for (int i = 0; i < 5; ++i) {
    auto frame = (*source)->next();
    ASSERT_TRUE(frame.is_ok() && frame->has_value());
    EXPECT_EQ((*frame)->sequence, i);
    EXPECT_EQ(cv::norm((*frame)->image, ramp(i % 2), cv::NORM_INF), 0);
  }

  TempDir empty;
  auto none = FrameSource::create("file:" + empty.path().string(), {});
  ASSERT_FALSE(none.is_ok());
  EXPECT_TRUE(contains(none.status().message(), "no image files"));

  TempDir mixed;
  ASSERT_TRUE(write_image(mixed / "a.png", ramp(0)).is_ok());
  ASSERT_TRUE(write_image(mixed / "b.png", cv::Mat(8, 8, CV_8U, cv::Scalar(1))).is_ok());
  auto m = FrameSource::create("file:" + mixed.path().string(), {});
  ASSERT_TRUE(m.is_ok());
  ASSERT_TRUE((*m)->next().is_ok());
  auto second = (*m)->next();
  ASSERT_FALSE(second.is_ok());
  EXPECT_TRUE(contains(second.status().message(), "b.png")) << second.status().message();

  TempDir session;
  std::FILE* f = std::fopen((session / "session.json").c_str(), "w");
  std::fputs("{}", f);
  std::fclose(f);
  auto s = FrameSource::create("file:" + session.path().string(), {});
  ASSERT_FALSE(s.is_ok());  // a broken session.json is named, never misread as images
  EXPECT_TRUE(contains(s.status().message(), "session.json")) << s.status().message();
  EXPECT_TRUE(contains(s.status().message(), "not a gvkit session")) << s.status().message();

  auto garbage_path = dir / "clip.avi";
  f = std::fopen(garbage_path.c_str(), "w");
  std::fputs("not a video", f);
  std::fclose(f);
  auto g = FrameSource::create("file:" + garbage_path.string(), {});
  ASSERT_FALSE(g.is_ok());
  EXPECT_TRUE(contains(g.status().message(), "not a video")) << g.status().message();
}

TEST(FileSource, ReplaysAVideoAsGrey) {
  TempDir dir;
  const std::string path = (dir / "clip.avi").string();
  {
    cv::VideoWriter writer(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 25,
                           cv::Size(32, 24), false);
    if (!writer.isOpened()) GTEST_SKIP() << "OpenCV's FFmpeg writer cannot write FFV1 here";
    for (int i = 0; i < 3; ++i) writer.write(ramp(i));
  }
  auto source = FrameSource::create("file:" + path, {});
  ASSERT_TRUE(source.is_ok()) << source.status().message();
  int n = 0;
  for (;; ++n) {
    auto frame = (*source)->next();
    ASSERT_TRUE(frame.is_ok());
    if (!frame->has_value()) break;
    EXPECT_EQ((*frame)->image.type(), CV_8U);
    EXPECT_EQ((*frame)->timestamp.count(), n * 40'000'000);  // the file's 25 fps
    // FFV1 is lossless; the grey conversion round trip may still differ by rounding.
    EXPECT_LE(cv::norm((*frame)->image, ramp(n), cv::NORM_INF), 1.0);
  }
  EXPECT_EQ(n, 3);
}

TEST(FileFrameSource, ReplaysASessionFolderWithPatternTags) {
  TempDir dir;
  capture::SessionInfo info;
  info.pattern = "psp3-f16";
  info.images_per_frame = 3;
  info.width = 32;
  info.height = 24;
  auto writer = capture::SessionWriter::create(dir / "s", info, capture::synthetic_calibration());
  ASSERT_TRUE(writer.is_ok()) << writer.status().message();
  for (int64_t index : {0, 1, 3}) {  // frame 2 was dropped by the recording
    FringeSet set;
    set.index = index;
    set.timestamp = Timestamp(1000 * index);
    for (int k = 0; k < 3; ++k) set.images.push_back(ramp(static_cast<int>(index) * 3 + k));
    ASSERT_TRUE((*writer)->append(set).is_ok());
  }
  ASSERT_TRUE((*writer)->add_dropped(1).is_ok());

  auto source = FrameSource::create("file:" + (dir / "s").string(), {});
  ASSERT_TRUE(source.is_ok()) << source.status().message();
  EXPECT_TRUE(contains((*source)->describe(), "session, 3 frames of 3 images"))
      << (*source)->describe();
  TaggedPatternSync sync({3, 3});
  std::vector<FringeSet> sets;
  int frames = 0;
  while (true) {
    auto frame = (*source)->next();
    ASSERT_TRUE(frame.is_ok()) << frame.status().message();
    if (!frame->has_value()) break;
    const CameraFrame& f = **frame;
    EXPECT_EQ(f.pattern, frames % 3);
    EXPECT_EQ(f.sequence / 3, std::vector<int64_t>({0, 1, 3})[frames / 3]);
    EXPECT_EQ(f.timestamp.count(), 1000 * (f.sequence / 3));
    ++frames;
    if (auto group = sync.push(f)) sets.push_back(to_fringe_set(std::move(*group)));
  }
  EXPECT_EQ(frames, 9);
  EXPECT_EQ((*source)->counters().dropped, 3);  // one dropped frame of 3 images
  ASSERT_EQ(sets.size(), 3u);
  EXPECT_EQ(sets[2].index, 3);
  for (const FringeSet& set : sets)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(cv::norm(set.images[static_cast<size_t>(k)],
                         ramp(static_cast<int>(set.index) * 3 + k), cv::NORM_INF),
                0);
  EXPECT_EQ(sync.counters().cycles_dropped, 0);
}

TEST(CallbackFrameSource, TagsPatternsAndDropsLateFramesLikeACamera) {
  FrameSourceOptions o;
  o.pattern_cycle = 4;
  o.cue_frames = 1;
  o.frame_count = 8;
  auto source = make_callback_source([](int64_t i) { return Result<cv::Mat>(ramp(int(i))); }, o);
  std::vector<int> tags;
  while (auto f = source->next()) {
    ASSERT_TRUE(f.is_ok());
    if (!f->has_value()) break;
    tags.push_back((*f)->pattern);
  }
  EXPECT_EQ(tags, std::vector<int>({-1, 0, 1, 2, -1, 0, 1, 2}));

  FrameSourceOptions paced;
  paced.fps = 100;
  paced.paced = true;
  paced.drop_late = true;
  auto late = make_callback_source([](int64_t i) { return Result<cv::Mat>(ramp(int(i))); }, paced);
  ASSERT_TRUE(late->next().is_ok());
  std::this_thread::sleep_for(std::chrono::milliseconds(55));  // ~5 slots pass unread
  auto f = late->next();
  ASSERT_TRUE(f.is_ok() && f->has_value());
  EXPECT_GE((*f)->sequence, 4);
  EXPECT_EQ(late->counters().dropped, (*f)->sequence - 1);
  paced.paced = false;
  EXPECT_TRUE(contains(paced.check().message(), "drop_late")) << paced.check().message();
}

}  // namespace
}  // namespace gvkit
