#include "gvkit/player/frame_prefetcher.hpp"

#include <atomic>
#include <mutex>
#include <set>
#include <thread>

#include <algorithm>

#include <gtest/gtest.h>

#include "player_test_data.hpp"

namespace gvkit::player {
namespace {

// In-memory sequence that records which frames were decoded, on which thread, and fails on
// request; it also flags any concurrent call to frame().
class FakeSequence : public FrameSequence {
 public:
  FakeSequence(int64_t n, int64_t bad) : n_(n), bad_(bad) {}
  std::string name() const override { return "fake"; }
  int64_t frame_count() const override { return n_; }
  double fps() const override { return 30; }
  Result<GeometryImage> frame(int64_t index) override {
    if (inside_.exchange(true)) concurrent_ = true;
    {
      std::lock_guard lock(mutex_);
      decoded_.push_back(index);
      threads_.insert(std::this_thread::get_id());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    inside_ = false;
    if (index == bad_) return corrupt_data("fake: frame " + std::to_string(index) + ": bad");
    GeometryImage image = testing::make_face_like_image(12, static_cast<int>(index));
    image.index = index;
    return image;
  }
  std::vector<int64_t> decoded() {
    std::lock_guard lock(mutex_);
    return decoded_;
  }
  std::set<std::thread::id> threads() {
    std::lock_guard lock(mutex_);
    return threads_;
  }
  std::atomic<bool> concurrent_{false};

 private:
  int64_t n_, bad_;
  std::atomic<bool> inside_{false};
  std::mutex mutex_;
  std::vector<int64_t> decoded_;
  std::set<std::thread::id> threads_;
};

TEST(FramePrefetcher, DecodesAheadOnOneWorkerThread) {
  auto seq = std::make_shared<FakeSequence>(20, -1);
  PrefetchOptions options;
  options.ahead = 4;
  options.capacity = 6;
  FramePrefetcher prefetcher(seq, options);
  auto f0 = prefetcher.get(0);
  ASSERT_TRUE(f0->status.is_ok());
  EXPECT_EQ(f0->index, 0);
  EXPECT_EQ(f0->image.index, 0);
  EXPECT_GT(f0->mesh.triangle_count(), 0u);
  prefetcher.wait_until_idle();
  EXPECT_EQ(seq->decoded(), (std::vector<int64_t>{0, 1, 2, 3, 4}));
  for (int i = 1; i <= 4; ++i) EXPECT_NE(prefetcher.try_get(i), nullptr) << i;
  const auto threads = seq->threads();
  ASSERT_EQ(threads.size(), 1u);
  EXPECT_NE(*threads.begin(), std::this_thread::get_id());
  EXPECT_FALSE(seq->concurrent_);
}

TEST(FramePrefetcher, CacheStaysBoundedAndSeekDecodesTheTargetFirst) {
  auto seq = std::make_shared<FakeSequence>(50, -1);
  PrefetchOptions options;
  options.ahead = 3;
  options.capacity = 5;
  FramePrefetcher prefetcher(seq, options);
  for (int i = 0; i < 12; ++i) {
    ASSERT_EQ(prefetcher.get(i)->index, i);
    EXPECT_LE(prefetcher.cached_count(), 5u);
    prefetcher.wait_until_idle();
  }
  EXPECT_EQ(prefetcher.misses(), 1);  // only frame 0 was waited for
  EXPECT_EQ(prefetcher.hits(), 11);
  prefetcher.wait_until_idle();
  const size_t before = seq->decoded().size();
  auto far = prefetcher.get(40);  // seek
  EXPECT_EQ(far->index, 40);
  prefetcher.wait_until_idle();
  const auto decoded = seq->decoded();
  ASSERT_GT(decoded.size(), before);
  EXPECT_EQ(decoded[before], 40);
  EXPECT_LE(prefetcher.cached_count(), 5u);
}

TEST(FramePrefetcher, LooksAheadAcrossTheEndOnlyWhenLooping) {
  auto seq = std::make_shared<FakeSequence>(6, -1);
  PrefetchOptions options;
  options.ahead = 3;
  options.capacity = 4;
  options.loop = false;
  {
    FramePrefetcher prefetcher(seq, options);
    // The worker may start on frame 0 before the first get(); what matters is what it decodes
    // once frame 4 is the target.
    auto decoded_from_4 = [&] {
      const auto d = seq->decoded();
      return std::vector<int64_t>(std::find(d.begin(), d.end(), 4), d.end());
    };
    prefetcher.get(4);
    prefetcher.wait_until_idle();
    EXPECT_EQ(decoded_from_4(), (std::vector<int64_t>{4, 5}));
    prefetcher.set_loop(true);
    prefetcher.wait_until_idle();
    // The wrapped look-ahead is 5 -> 0 -> 1: frames 0 and 1 are cached now (decoded in the wrap,
    // or before the first get() if the worker started on frame 0 and they stayed), and no frame
    // beyond the window was decoded once frame 4 was the target.
    const auto tail = decoded_from_4();
    EXPECT_EQ(std::count(tail.begin(), tail.end(), 2), 0);
    EXPECT_EQ(std::count(tail.begin(), tail.end(), 3), 0);
    EXPECT_LE(std::count(tail.begin(), tail.end(), 0), 1);
    EXPECT_LE(std::count(tail.begin(), tail.end(), 1), 1);
    const int64_t hits = prefetcher.hits();
    EXPECT_NE(prefetcher.try_get(0), nullptr);  // moves the window to 0 .. 2; 1 stays in it
    EXPECT_NE(prefetcher.try_get(1), nullptr);
    EXPECT_EQ(prefetcher.hits(), hits + 2);
  }
}

TEST(FramePrefetcher, FailedFrameCarriesItsStatusAndOthersStillPlay) {
  auto seq = std::make_shared<FakeSequence>(5, 2);
  FramePrefetcher prefetcher(seq, {});
  EXPECT_TRUE(prefetcher.get(1)->status.is_ok());
  auto bad = prefetcher.get(2);
  EXPECT_FALSE(bad->status.is_ok());
  EXPECT_NE(bad->status.message().find("frame 2"), std::string::npos);
  EXPECT_EQ(bad->mesh.vertex_count(), 0u);
  EXPECT_TRUE(prefetcher.get(3)->status.is_ok());
}

TEST(FramePrefetcher, OptionsAreChecked) {
  PrefetchOptions options;
  options.ahead = 8;
  options.capacity = 4;
  EXPECT_FALSE(options.check().is_ok());
  options.ahead = -1;
  EXPECT_FALSE(options.check().is_ok());
}

}  // namespace
}  // namespace gvkit::player
