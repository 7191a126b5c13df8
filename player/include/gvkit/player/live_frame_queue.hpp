#pragma once
// LiveFrameQueue: the live-preview hook. A producer (the capture pipeline, on any thread) pushes
// GeometryImages or RangeScans; the player window (or any consumer) takes the newest one each
// time it draws. The queue is bounded and never blocks the producer: when it is full the oldest
// pending frame is dropped and counted, so a slow viewer cannot stall a camera.
//
//   auto queue = std::make_shared<gvkit::player::LiveFrameQueue>();
//   std::thread viewer([&] { run_player_window(options_with(queue)); });  // window
//   for (...) queue->push(scan);   // capture thread; push(GeometryImage) from facemap
//   queue->close();                // no more frames; the window keeps showing the last one

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>

#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/range_scan.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::player {

class LiveFrameQueue {
 public:
  // capacity >= 1 pending frames (contract).
  explicit LiveFrameQueue(size_t capacity = 2);

  // Producer side; thread-safe. The frame must pass check() (contract for GeometryImage; a
  // RangeScan failing check() is refused with its Status). Pushing after close() is ignored.
  void push(GeometryImage frame);
  Status push(const RangeScan& scan);
  void close();

  // Consumer side; thread-safe. The newest pending frame (older pending ones count as dropped),
  // or nothing when none arrived since the last call.
  std::optional<GeometryImage> take_latest();
  // Like take_latest, waiting up to `timeout` for a frame; nothing on timeout or when closed.
  std::optional<GeometryImage> wait_latest(std::chrono::milliseconds timeout);

  bool closed() const;
  int64_t pushed() const;   // frames accepted by push
  int64_t dropped() const;  // frames never taken (overflow or superseded)
  size_t pending() const;   // frames pushed and not yet taken

 private:
  const size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<GeometryImage> pending_;
  bool closed_ = false;
  int64_t pushed_ = 0, dropped_ = 0;
};

}  // namespace gvkit::player
