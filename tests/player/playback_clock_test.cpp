#include "gvkit/player/playback_clock.hpp"

#include <gtest/gtest.h>

namespace gvkit::player {
namespace {

using std::chrono::milliseconds;

// A clock the test moves by hand.
struct FakeClock {
  Timestamp now{std::chrono::seconds(1000)};
  PlaybackClock::NowFn fn() {
    return [this] { return now; };
  }
  void advance(milliseconds d) { now += d; }
};

TEST(PlaybackClock, StartsPausedAndAdvancesWithTimeWhilePlaying) {
  FakeClock t;
  PlaybackClock clock(10, 10.0, t.fn());  // 100 ms per frame, 1 s long
  EXPECT_FALSE(clock.playing());
  t.advance(milliseconds(500));
  EXPECT_EQ(clock.current_frame(), 0);
  clock.play();
  t.advance(milliseconds(250));
  EXPECT_EQ(clock.current_frame(), 2);
  t.advance(milliseconds(60));
  EXPECT_EQ(clock.current_frame(), 3);
  clock.pause();
  t.advance(milliseconds(5000));
  EXPECT_EQ(clock.current_frame(), 3);
  EXPECT_EQ(clock.position(), milliseconds(310));
}

TEST(PlaybackClock, LoopsOrStopsAtTheEnd) {
  FakeClock t;
  PlaybackClock clock(10, 10.0, t.fn());
  clock.play();
  t.advance(milliseconds(1230));
  EXPECT_EQ(clock.current_frame(), 2);  // wrapped once
  EXPECT_TRUE(clock.playing());

  clock.set_loop(false);
  clock.seek(8);
  t.advance(milliseconds(700));
  EXPECT_EQ(clock.current_frame(), 9);
  EXPECT_FALSE(clock.playing());  // reached the end and stopped
  t.advance(milliseconds(700));
  EXPECT_EQ(clock.current_frame(), 9);
  clock.play();  // starts over
  EXPECT_EQ(clock.current_frame(), 0);
}

TEST(PlaybackClock, SpeedScalesTimeAndRejectsNonPositive) {
  FakeClock t;
  PlaybackClock clock(100, 10.0, t.fn());
  ASSERT_TRUE(clock.set_speed(2.0).is_ok());
  clock.play();
  t.advance(milliseconds(500));
  EXPECT_EQ(clock.current_frame(), 10);
  ASSERT_TRUE(clock.set_speed(0.5).is_ok());  // keeps the position where the speed changed
  t.advance(milliseconds(400));
  EXPECT_EQ(clock.current_frame(), 12);
  EXPECT_FALSE(clock.set_speed(0).is_ok());
  EXPECT_FALSE(clock.set_speed(-1).is_ok());
  EXPECT_DOUBLE_EQ(clock.speed(), 0.5);
}

TEST(PlaybackClock, SeekAndStep) {
  FakeClock t;
  PlaybackClock clock(5, 25.0, t.fn());
  clock.seek(3);
  EXPECT_EQ(clock.current_frame(), 3);
  clock.seek(99);
  EXPECT_EQ(clock.current_frame(), 4);
  clock.seek(-3);
  EXPECT_EQ(clock.current_frame(), 0);
  clock.play();
  clock.step(1);
  EXPECT_FALSE(clock.playing());  // stepping pauses
  EXPECT_EQ(clock.current_frame(), 1);
  clock.step(-2);  // loops backwards
  EXPECT_EQ(clock.current_frame(), 4);
  clock.set_loop(false);
  clock.step(3);
  EXPECT_EQ(clock.current_frame(), 4);
  clock.seek_time(milliseconds(81));
  EXPECT_EQ(clock.current_frame(), 2);
  clock.seek_time(std::chrono::seconds(10));
  EXPECT_EQ(clock.current_frame(), 4);
}

TEST(PlaybackClock, UnevenTimestampsChooseFramesByTime) {
  FakeClock t;
  // A dropped frame between 1 and 2: frame 2 comes 200 ms after frame 1.
  std::vector<Timestamp> ts = {milliseconds(5000), milliseconds(5100), milliseconds(5300),
                               milliseconds(5400)};
  PlaybackClock clock(ts, 10.0, t.fn());
  EXPECT_EQ(clock.duration(), milliseconds(500));
  clock.play();
  t.advance(milliseconds(250));
  EXPECT_EQ(clock.current_frame(), 1);
  t.advance(milliseconds(60));
  EXPECT_EQ(clock.current_frame(), 2);
  EXPECT_EQ(frame_at_time(ts, milliseconds(0)), 0);
  EXPECT_EQ(frame_at_time(ts, milliseconds(5399)), 2);
  EXPECT_EQ(frame_at_time(ts, milliseconds(9999)), 3);
}

TEST(PlaybackClock, ContractViolationsThrow) {
  EXPECT_THROW(PlaybackClock(0, 30.0), ContractError);
  EXPECT_THROW(PlaybackClock(5, 0.0), ContractError);
  EXPECT_THROW(PlaybackClock(std::vector<Timestamp>{milliseconds(2), milliseconds(1)}, 30.0),
               ContractError);
}

}  // namespace
}  // namespace gvkit::player
