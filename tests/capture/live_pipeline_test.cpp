// The live pipeline with a generated source: every frame is accounted for (processed or counted
// as dropped) under each queue policy, failures stop it with the stage's name, limits hold, and
// the status line carries the figures.
#include "gvkit/capture/live_pipeline.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "gvkit/capture/callback_frame_source.hpp"

namespace gvkit {
namespace {
using std::chrono::milliseconds;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::unique_ptr<FrameSource> counting_source(int64_t n) {
  FrameSourceOptions o;
  o.frame_count = n;
  return make_callback_source(
      [](int64_t i) -> Result<cv::Mat> {
        return cv::Mat(8, 8, CV_8U, cv::Scalar(static_cast<double>(i % 256)));
      },
      o, "synthetic:test");
}

// A stage that sleeps (a slow reconstruction) and records the frame sequences it saw.
LiveStage slow_stage(std::vector<int64_t>* seen, milliseconds delay, size_t capacity,
                     QueueFullPolicy policy) {
  LiveStage stage;
  stage.name = "slow";
  stage.queue_capacity = capacity;
  stage.when_full = policy;
  stage.run = [seen, delay](std::any&& value) -> Result<std::optional<std::any>> {
    const auto& frame = std::any_cast<const CameraFrame&>(value);
    seen->push_back(frame.sequence);
    std::this_thread::sleep_for(delay);
    return std::optional<std::any>(frame.sequence);
  };
  return stage;
}

TEST(BoundedQueue, PoliciesCountEveryDrop) {
  BoundedQueue<int> oldest(2, QueueFullPolicy::kDropOldest);
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(oldest.push(i));
  EXPECT_EQ(oldest.dropped(), 3);
  EXPECT_EQ(*oldest.pop(), 3);
  EXPECT_EQ(*oldest.pop(), 4);
  BoundedQueue<int> newest(2, QueueFullPolicy::kDropNewest);
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(newest.push(i));
  EXPECT_EQ(newest.dropped(), 3);
  EXPECT_EQ(*newest.pop(), 0);
  newest.close();
  EXPECT_FALSE(newest.push(9));
  EXPECT_EQ(*newest.pop(), 1);
  EXPECT_FALSE(newest.pop().has_value());
  EXPECT_EQ(parse_queue_full_policy("drop-oldest").value(), QueueFullPolicy::kDropOldest);
  EXPECT_TRUE(contains(parse_queue_full_policy("lifo").status().message(), "'lifo'"));
}

TEST(LivePipeline, SlowConsumerDropsAreCountedNeverSilent) {
  std::vector<int64_t> seen;
  std::vector<int64_t> finished;
  LiveStage sink;
  sink.name = "sink";
  sink.queue_capacity = 64;
  sink.when_full = QueueFullPolicy::kBlock;
  sink.run = [&finished](std::any&& v) -> Result<std::optional<std::any>> {
    finished.push_back(std::any_cast<int64_t>(v));
    return std::optional<std::any>();
  };
  LivePipeline pipeline(counting_source(60),
                        {slow_stage(&seen, milliseconds(3), 2, QueueFullPolicy::kDropOldest), sink},
                        {});
  ASSERT_TRUE(pipeline.start().is_ok());
  ASSERT_TRUE(pipeline.wait().is_ok());
  const LiveStatus s = pipeline.status();
  EXPECT_EQ(s.captured, 60);
  ASSERT_EQ(s.stages.size(), 2u);
  EXPECT_GT(s.stages[0].dropped, 0);  // the source is far faster than 3 ms per frame
  EXPECT_EQ(s.stages[0].in + s.stages[0].dropped, 60);
  EXPECT_EQ(static_cast<int64_t>(seen.size()), s.stages[0].in);
  EXPECT_EQ(s.stages[1].in, s.stages[0].out);
  EXPECT_EQ(finished, seen);   // order kept, nothing lost after the counted drops
  EXPECT_EQ(seen.back(), 59);  // drop-oldest keeps the freshest frame
  EXPECT_LE(s.stages[0].max_queue_depth, 2u);
  EXPECT_GT(s.stages[0].latency_mean_ms, 0);
  EXPECT_GE(s.stages[0].latency_max_ms, s.stages[0].latency_mean_ms);
}

TEST(LivePipeline, BlockingQueuesLoseNothing) {
  std::vector<int64_t> seen;
  LivePipeline pipeline(counting_source(40),
                        {slow_stage(&seen, milliseconds(1), 2, QueueFullPolicy::kBlock)}, {});
  ASSERT_TRUE(pipeline.start().is_ok());
  ASSERT_TRUE(pipeline.wait().is_ok());
  const LiveStatus s = pipeline.status();
  EXPECT_EQ(s.stages[0].dropped, 0);
  EXPECT_EQ(s.stages[0].out, 40);
  ASSERT_EQ(seen.size(), 40u);
  for (int64_t i = 0; i < 40; ++i) EXPECT_EQ(seen[static_cast<size_t>(i)], i);
}

TEST(LivePipeline, AFailingStageStopsEverythingWithItsName) {
  LiveStage broken;
  broken.name = "reconstruct";
  broken.run = [](std::any&& v) -> Result<std::optional<std::any>> {
    if (std::any_cast<const CameraFrame&>(v).sequence == 5)
      return failed_precondition("frame 5: no fringe modulation");
    return std::optional<std::any>(0);
  };
  broken.when_full = QueueFullPolicy::kBlock;
  LivePipeline pipeline(counting_source(1000000), {broken}, {});
  ASSERT_TRUE(pipeline.start().is_ok());
  const Status s = pipeline.wait();
  EXPECT_EQ(s.message(), "reconstruct: frame 5: no fringe modulation");
  EXPECT_LT(pipeline.status().captured, 1000000);
}

TEST(LivePipeline, SourceFailuresAndLimits) {
  FrameSourceOptions o;
  auto failing = make_callback_source(
      [](int64_t i) -> Result<cv::Mat> {
        if (i == 3) return io_error("device vanished");
        return cv::Mat(2, 2, CV_8U, cv::Scalar(0));
      },
      o, "v4l2:/dev/video0");
  LivePipeline a(std::move(failing), {}, {});
  ASSERT_TRUE(a.start().is_ok());
  EXPECT_EQ(a.wait().message(), "v4l2:/dev/video0: frame 3: device vanished");
  EXPECT_EQ(a.status().captured, 3);

  LivePipelineOptions limit;
  limit.max_frames = 7;
  std::vector<int64_t> seen;
  LivePipeline b(counting_source(100),
                 {slow_stage(&seen, milliseconds(0), 4, QueueFullPolicy::kBlock)}, limit);
  ASSERT_TRUE(b.start().is_ok());
  ASSERT_TRUE(b.wait().is_ok());
  EXPECT_EQ(b.status().captured, 7);
  EXPECT_EQ(seen.size(), 7u);

  LivePipelineOptions bad;
  bad.max_seconds = -1;
  LivePipeline c(counting_source(1), {}, bad);
  EXPECT_FALSE(c.start().is_ok());
}

TEST(LivePipeline, StatusLineIsReportedWhileRunningAndAtTheEnd) {
  FrameSourceOptions o;
  o.fps = 200;
  o.paced = true;
  o.frame_count = 40;  // 0.2 s
  auto source = make_callback_source(
      [](int64_t) -> Result<cv::Mat> { return cv::Mat(2, 2, CV_8U, cv::Scalar(0)); }, o);
  std::vector<std::string> lines;
  std::mutex mutex;
  LivePipelineOptions options;
  options.status_interval_s = 0.05;
  options.on_status = [&](const LiveStatus& s) {
    std::lock_guard<std::mutex> lock(mutex);
    lines.push_back(s.line());
  };
  std::vector<int64_t> seen;
  LivePipeline pipeline(std::move(source),
                        {slow_stage(&seen, milliseconds(0), 4, QueueFullPolicy::kBlock)}, options);
  ASSERT_TRUE(pipeline.start().is_ok());
  ASSERT_TRUE(pipeline.wait().is_ok());
  ASSERT_GE(lines.size(), 2u);  // at least one while running, one final
  const std::string& last = lines.back();
  EXPECT_TRUE(contains(last, "in ")) << last;
  EXPECT_TRUE(contains(last, "slow: out ")) << last;
  EXPECT_TRUE(contains(last, "drop 0")) << last;
  EXPECT_TRUE(contains(last, "source drop 0 err 0")) << last;
  EXPECT_EQ(pipeline.status().captured, 40);
  EXPECT_GT(pipeline.status().elapsed_s, 0.15);  // paced: 40 frames at 200 fps take >= 195 ms
}

}  // namespace
}  // namespace gvkit
