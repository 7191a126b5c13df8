// The V4L2 source against a fake driver (no camera exists on the build machines): formats and
// strides, retries, error buffers, drops, timestamps, a vanishing device and bad input. With
// GVKIT_TEST_V4L2_DEVICE=/dev/videoN set, one more test streams from that real device.
#include "gvkit/capture/v4l2_source.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

#include "fake_v4l2_driver.hpp"
#include "gvkit/capture/v4l2_devices.hpp"

namespace gvkit {
namespace {
using testing::FakeEvent;
using testing::FakeV4l2Driver;
using testing::frames;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::shared_ptr<FakeV4l2Driver> fake_with(std::deque<FakeEvent> script) {
  auto fake = std::make_shared<FakeV4l2Driver>();
  fake->script = std::move(script);
  return fake;
}

Result<std::unique_ptr<FrameSource>> open(std::shared_ptr<FakeV4l2Driver> fake,
                                          FrameSourceOptions options = {}) {
  options.timeout_ms = 50;
  return open_v4l2_source(fake->path, options, fake);
}

// Reads frames until the source fails (the fake's script ran out: a timeout) and checks each
// against the fake's pattern.
std::vector<CameraFrame> drain(FrameSource& source, const FakeV4l2Driver& fake,
                               Status* end = nullptr) {
  std::vector<CameraFrame> out;
  for (;;) {
    auto frame = source.next();
    if (!frame.is_ok()) {
      if (end) *end = frame.status();
      return out;
    }
    EXPECT_TRUE(frame->has_value());
    const cv::Mat expected = fake.expected(static_cast<uint32_t>((*frame)->sequence));
    EXPECT_EQ((*frame)->image.type(), expected.type());
    EXPECT_EQ(cv::norm((*frame)->image, expected, cv::NORM_INF), 0)
        << "frame " << (*frame)->sequence;
    out.push_back(std::move(**frame));
  }
}

TEST(V4l2Source, GreyWithPaddedStrideIsBitExact) {
  auto fake = fake_with(frames(5));
  auto source = open(fake);
  ASSERT_TRUE(source.is_ok()) << source.status().message();
  EXPECT_TRUE(fake->streaming);
  EXPECT_EQ((*source)->describe(),
            "v4l2:/dev/video7 (fakecam 'Fake Camera') 33x7 GREY stride 40, "
            "30.000000 fps");
  Status end;
  auto got = drain(**source, *fake, &end);
  ASSERT_EQ(got.size(), 5u);
  EXPECT_TRUE(contains(end.message(), "no frame within 50 ms")) << end.message();
  EXPECT_EQ((*source)->counters().frames, 5);
  EXPECT_EQ((*source)->counters().dropped, 0);
  EXPECT_EQ(got[2].timestamp.count(), 1'000'000'000 + 2 * 33'333'000);  // us resolution
  source->reset();
  EXPECT_TRUE(fake->stream_off);
  EXPECT_TRUE(fake->closed);
  EXPECT_EQ(fake->mapped, fake->unmapped);
}

TEST(V4l2Source, Y16WithAnOddStrideAndYuyvLuma) {
  auto y16 = fake_with(frames(3));
  y16->formats = {V4L2_PIX_FMT_Y16};
  y16->stride_padding = 3;  // odd bytesperline: rows start at odd addresses
  FrameSourceOptions o;
  o.pixel_format = "Y16";
  auto a = open(y16, o);
  ASSERT_TRUE(a.is_ok()) << a.status().message();
  EXPECT_EQ(drain(**a, *y16).size(), 3u);

  auto yuyv = fake_with(frames(3));
  yuyv->formats = {V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_YUYV};
  auto b = open(yuyv);  // auto prefers YUYV to MJPEG
  ASSERT_TRUE(b.is_ok()) << b.status().message();
  EXPECT_TRUE(contains((*b)->describe(), "YUYV"));
  EXPECT_EQ(drain(**b, *yuyv).size(), 3u);
}

TEST(V4l2Source, MjpegIsDecodedToGrey) {
  auto fake = fake_with(frames(2));
  fake->formats = {V4L2_PIX_FMT_MJPEG};
  fake->width = 32;
  fake->height = 16;
  auto source = open(fake);
  ASSERT_TRUE(source.is_ok()) << source.status().message();
  for (uint32_t i = 0; i < 2; ++i) {
    auto frame = (*source)->next();
    ASSERT_TRUE(frame.is_ok()) << frame.status().message();
    ASSERT_EQ((*frame)->image.type(), CV_8U);
    EXPECT_LE(cv::norm((*frame)->image, fake->expected(i), cv::NORM_INF), 12);  // JPEG q100
  }
}

TEST(V4l2Source, RetriesEagainAndEintr) {
  std::deque<FakeEvent> script = frames(4);
  script.insert(script.begin() + 1, FakeEvent{FakeEvent::kDqbufErrno, EAGAIN});
  script.insert(script.begin() + 2, FakeEvent{FakeEvent::kDqbufErrno, EINTR});
  script.insert(script.begin() + 3, FakeEvent{FakeEvent::kPollErrno, EINTR});
  auto fake = fake_with(script);
  auto source = open(fake);
  ASSERT_TRUE(source.is_ok());
  EXPECT_EQ(drain(**source, *fake).size(), 4u);
  EXPECT_EQ((*source)->counters().retries, 3);
  EXPECT_EQ((*source)->counters().errored, 0);
}

TEST(V4l2Source, ErrorBuffersAreDiscardedAndSequenceGapsCountAsDrops) {
  std::deque<FakeEvent> script = frames(3);         // 0 1 2
  for (auto e : frames(2, 6)) script.push_back(e);  // 6 7: frames 3..5 never arrived
  script[1].flags = V4L2_BUF_FLAG_ERROR;            // frame 1 arrives broken
  script[3].bytes_used = 10;                        // frame 6 is too short to be a frame
  auto fake = fake_with(script);
  auto source = open(fake);
  ASSERT_TRUE(source.is_ok());
  auto got = drain(**source, *fake);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[0].sequence, 0);
  EXPECT_EQ(got[1].sequence, 2);
  EXPECT_EQ(got[2].sequence, 7);
  const FrameSourceCounters c = (*source)->counters();
  EXPECT_EQ(c.frames, 3);
  EXPECT_EQ(c.errored, 2);
  EXPECT_EQ(c.dropped, 3);
}

TEST(V4l2Source, TimestampsNeverGoBackwards) {
  std::deque<FakeEvent> script = frames(5);
  script[1].timestamp_ns += 4'000'000;   // jitter
  script[2].timestamp_ns -= 3'000'000;   // jitter
  script[3].timestamp_ns = 900'000'000;  // jumps back before frame 0
  auto fake = fake_with(script);
  auto source = open(fake);
  ASSERT_TRUE(source.is_ok());
  auto got = drain(**source, *fake);
  ASSERT_EQ(got.size(), 5u);
  for (size_t i = 1; i < got.size(); ++i) EXPECT_GE(got[i].timestamp, got[i - 1].timestamp);
  EXPECT_EQ(got[3].timestamp, got[2].timestamp);  // clamped
  EXPECT_EQ((*source)->counters().clamped_timestamps, 1);

  // A driver without monotonic buffer timestamps: the time of dequeue is used instead.
  auto unknown = fake_with(frames(2));
  unknown->timestamps_monotonic = false;
  auto s = open(unknown);
  ASSERT_TRUE(s.is_ok());
  const Timestamp before = monotonic_now();
  auto f = drain(**s, *unknown);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_GE(f[0].timestamp, before);
  EXPECT_LE(f[1].timestamp, monotonic_now());
}

TEST(V4l2Source, DeviceVanishingMidStreamEndsWithAClearStatus) {
  std::deque<FakeEvent> script = frames(2);
  script.push_back(FakeEvent{FakeEvent::kVanish});
  auto fake = fake_with(script);
  auto source = open(fake);
  ASSERT_TRUE(source.is_ok());
  Status end;
  EXPECT_EQ(drain(**source, *fake, &end).size(), 2u);
  EXPECT_EQ(end.code(), StatusCode::kIoError);
  EXPECT_TRUE(contains(end.message(), "/dev/video7: VIDIOC_DQBUF: the device vanished"))
      << end.message();
  auto again = (*source)->next();
  EXPECT_FALSE(again.is_ok());
  source->reset();  // teardown against a vanished device must not crash
  EXPECT_TRUE(fake->closed);
}

TEST(V4l2Source, RefusedFormatsListTheSupportedOnes) {
  auto fake = fake_with({});
  FrameSourceOptions o;
  o.pixel_format = "Y16";
  auto missing = open(fake, o);
  ASSERT_FALSE(missing.is_ok());
  EXPECT_EQ(missing.status().code(), StatusCode::kUnsupported);
  EXPECT_TRUE(contains(missing.status().message(),
                       "pixel format Y16 is not offered; the device "
                       "offers GREY, YUYV; gvkit reads GREY, Y16"))
      << missing.status().message();

  auto substitutes = fake_with({});
  substitutes->s_fmt_substitutes[V4L2_PIX_FMT_GREY] = V4L2_PIX_FMT_YUYV;
  auto changed = open(substitutes);
  ASSERT_FALSE(changed.is_ok());
  EXPECT_TRUE(contains(changed.status().message(),
                       "the driver refused pixel format GREY and offered YUYV instead"))
      << changed.status().message();

  auto rgb = fake_with({});
  rgb->formats = {V4L2_PIX_FMT_RGB24, V4L2_PIX_FMT_NV12};
  auto none = open(rgb);
  ASSERT_FALSE(none.is_ok());
  EXPECT_TRUE(contains(none.status().message(), "the device offers RGB3, NV12"))
      << none.status().message();
}

TEST(V4l2Source, BadDevicesGiveClearStatuses) {
  const std::pair<int, std::string> cases[] = {
      {ENOENT, "no such device"}, {EACCES, "permission denied"}, {EBUSY, "device busy"}};
  for (const auto& [error, words] : cases) {
    auto fake = fake_with({});
    fake->open_errno = error;
    auto r = open(fake);
    ASSERT_FALSE(r.is_ok());
    EXPECT_TRUE(contains(r.status().message(), "/dev/video7: open: " + words))
        << r.status().message();
  }
  auto output = fake_with({});
  output->capabilities = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING;
  auto r = open(output);
  ASSERT_FALSE(r.is_ok());
  EXPECT_TRUE(contains(r.status().message(), "not a video capture device"));
}

TEST(V4l2Source, FpsAndExposureAreAppliedOrReportedAsRefused) {
  auto fake = fake_with({});
  FrameSourceOptions o;
  o.fps = 50;
  o.exposure_us = 2000;
  auto ok = open(fake, o);
  ASSERT_TRUE(ok.is_ok());
  EXPECT_TRUE((*ok)->refused_settings().empty());
  EXPECT_DOUBLE_EQ(fake->fps, 50);
  EXPECT_EQ(fake->exposure, 20);
  EXPECT_EQ(fake->exposure_mode, V4L2_EXPOSURE_MANUAL);

  auto limited = fake_with({});
  limited->max_fps = 30;
  limited->exposure_max = 10;
  o.fps = 90;
  o.width = 640;
  o.height = 480;
  auto r = open(limited, o);
  ASSERT_TRUE(r.is_ok());
  const auto refused = (*r)->refused_settings();
  ASSERT_EQ(refused.size(), 3u);
  EXPECT_TRUE(contains(refused[0], "size: asked 640x480, the driver gave 64x48"));
  EXPECT_TRUE(contains(refused[1], "fps: asked 90")) << refused[1];
  EXPECT_TRUE(contains(refused[2], "exposure: asked 2000")) << refused[2];

  auto fixed = fake_with({});
  fixed->can_set_fps = false;
  fixed->has_exposure = false;
  o = {};
  o.fps = 25;
  o.exposure_us = 500;
  auto f = open(fixed, o);
  ASSERT_TRUE(f.is_ok());
  ASSERT_EQ((*f)->refused_settings().size(), 2u);
  EXPECT_TRUE(contains((*f)->refused_settings()[0], "does not set frame rates"));
  EXPECT_TRUE(contains((*f)->refused_settings()[1], "no V4L2_CID_EXPOSURE_ABSOLUTE"));
}

TEST(V4l2Devices, ListsFormatsSizesAndRates) {
  FakeV4l2Driver fake;
  fake.formats = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_RGB24};
  auto info = query_v4l2_device(fake.path, fake);
  ASSERT_TRUE(info.is_ok()) << info.status().message();
  EXPECT_EQ(info->driver, "fakecam");
  EXPECT_EQ(info->card, "Fake Camera");
  EXPECT_TRUE(info->capture);
  ASSERT_EQ(info->formats.size(), 2u);
  EXPECT_EQ(info->formats[0].fourcc, "YUYV");
  EXPECT_TRUE(info->formats[0].readable);
  EXPECT_FALSE(info->formats[1].readable);
  ASSERT_EQ(info->formats[0].sizes.size(), 2u);
  EXPECT_EQ(info->formats[0].sizes[1].size, "1280x720");
  EXPECT_EQ(info->formats[0].sizes[1].rates, (std::vector<std::string>{"30 fps", "60 fps"}));
  EXPECT_TRUE(fake.closed);

  fake.open_errno = EACCES;
  auto denied = query_v4l2_device(fake.path, fake);
  ASSERT_FALSE(denied.is_ok());
  EXPECT_TRUE(contains(denied.status().message(), "permission denied"));
}

TEST(V4l2Source, RealDevice) {
  const char* device = std::getenv("GVKIT_TEST_V4L2_DEVICE");
  if (!device) GTEST_SKIP() << "set GVKIT_TEST_V4L2_DEVICE=/dev/videoN to stream from a camera";
  auto source = open_v4l2_source(device, {});
  ASSERT_TRUE(source.is_ok()) << source.status().message();
  Timestamp last{0};
  for (int i = 0; i < 10; ++i) {
    auto frame = (*source)->next();
    ASSERT_TRUE(frame.is_ok()) << frame.status().message();
    ASSERT_TRUE(frame->has_value());
    EXPECT_FALSE((*frame)->image.empty());
    EXPECT_GE((*frame)->timestamp, last);
    last = (*frame)->timestamp;
  }
}

}  // namespace
}  // namespace gvkit
