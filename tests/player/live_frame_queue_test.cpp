#include "gvkit/player/live_frame_queue.hpp"

#include <thread>

#include <gtest/gtest.h>

#include "player_test_data.hpp"

namespace gvkit::player {
namespace {

TEST(LiveFrameQueue, ConsumerGetsTheNewestFrameAndOlderOnesCountAsDropped) {
  LiveFrameQueue queue(3);
  EXPECT_FALSE(queue.take_latest().has_value());
  for (int i = 0; i < 5; ++i) queue.push(testing::make_face_like_image(8, i));
  auto latest = queue.take_latest();
  ASSERT_TRUE(latest.has_value());
  EXPECT_EQ(latest->index, 4);
  EXPECT_EQ(queue.pushed(), 5);
  EXPECT_EQ(queue.dropped(), 4);  // 2 by overflow, 2 superseded
  EXPECT_FALSE(queue.take_latest().has_value());
}

TEST(LiveFrameQueue, AcceptsRangeScansAndRefusesBrokenOnes) {
  LiveFrameQueue queue;
  RangeScan scan;
  scan.xyz_mm = cv::Mat(4, 4, CV_32FC3, cv::Scalar(0, 0, 500));
  scan.valid = cv::Mat(4, 4, CV_8U, cv::Scalar(255));
  scan.texture = cv::Mat(4, 4, CV_32F, cv::Scalar(0.5));
  scan.quality = cv::Mat(4, 4, CV_32F, cv::Scalar(1));
  scan.index = 7;
  ASSERT_TRUE(queue.push(scan).is_ok());
  scan.valid = cv::Mat(3, 3, CV_8U, cv::Scalar(255));  // wrong size
  EXPECT_FALSE(queue.push(scan).is_ok());
  auto frame = queue.take_latest();
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->index, 7);
  EXPECT_EQ(cv::countNonZero(frame->domain_mask), 16);
}

TEST(LiveFrameQueue, ProducerThreadAndWaitingConsumer) {
  LiveFrameQueue queue(2);
  std::thread producer([&] {
    for (int i = 0; i < 20; ++i) queue.push(testing::make_face_like_image(8, i));
    queue.close();
  });
  int64_t last = -1, taken = 0;
  while (true) {
    auto f = queue.wait_latest(std::chrono::milliseconds(50));
    if (f) {
      EXPECT_GT(f->index, last);  // frames arrive in order, never repeated
      last = f->index;
      ++taken;
    } else if (queue.closed()) {
      break;
    }
  }
  producer.join();
  if (auto f = queue.take_latest()) last = f->index, ++taken;
  EXPECT_EQ(last, 19);
  EXPECT_EQ(taken + queue.dropped(), 20);
  queue.push(testing::make_face_like_image(8, 99));  // ignored after close
  EXPECT_EQ(queue.pushed(), 20);
}

}  // namespace
}  // namespace gvkit::player
