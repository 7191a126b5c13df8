#pragma once
// LivePipeline: a capture thread reading a FrameSource, then processing stages (sync,
// reconstruct, preview, record, ...) each on its own thread, joined by bounded queues. A slow
// stage either slows capture (kBlock) or drops frames (kDropOldest / kDropNewest) - always
// counted and shown in the status line, never silent.

#include <any>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "gvkit/capture/bounded_queue.hpp"
#include "gvkit/capture/frame_source.hpp"

namespace gvkit {

// What travels between stages: the capture index and arrival time of the frame that started it
// (for latency) and the stage's value (a CameraFrame out of the capture thread; whatever a stage
// returns after that).
struct LivePacket {
  int64_t index = 0;
  Timestamp arrived{0};  // monotonic time the capture thread received the frame
  std::any value;
};

// A stage consumes a packet's value and returns the value to pass on, std::nullopt to pass
// nothing on (e.g. a sync stage still collecting a pattern cycle), or a Status that stops the
// pipeline.
using LiveStageFunction = std::function<Result<std::optional<std::any>>(std::any&& value)>;

struct LiveStage {
  std::string name;
  LiveStageFunction run;
  size_t queue_capacity = 4;  // the queue in front of this stage
  QueueFullPolicy when_full = QueueFullPolicy::kDropOldest;
};

struct LiveStatus;

struct LivePipelineOptions {
  int64_t max_frames = 0;        // stop capturing after this many frames (0 = until the end)
  double max_seconds = 0;        // stop capturing after this long (0 = no limit)
  double status_interval_s = 1;  // how often on_status is called (0 = never)
  std::function<void(const LiveStatus&)> on_status;  // from a status thread
  Status check() const;
};

struct LiveStageStatus {
  std::string name;
  int64_t in = 0;       // values taken from the queue
  int64_t out = 0;      // values passed on
  int64_t dropped = 0;  // values evicted or rejected by the full queue in front of the stage
  size_t queue_depth = 0, queue_capacity = 0, max_queue_depth = 0;
  double latency_mean_ms = 0, latency_max_ms = 0;  // capture arrival -> value passed on
};

struct LiveStatus {
  double elapsed_s = 0;
  int64_t captured = 0;
  FrameSourceCounters source;
  std::vector<LiveStageStatus> stages;
  bool running = false;
  // "12.0 s | in 30.0 fps | reconstruct: out 29.9 fps q 1/4 (max 3) drop 0 lat 41.2 ms (max
  // 60.3) | source drop 0 err 0"
  std::string line() const;
};

class LivePipeline {
 public:
  LivePipeline(std::unique_ptr<FrameSource> source, std::vector<LiveStage> stages,
               LivePipelineOptions options);
  ~LivePipeline();  // stops and joins
  LivePipeline(const LivePipeline&) = delete;
  LivePipeline& operator=(const LivePipeline&) = delete;

  Status start();
  // Asks the capture thread to stop; the stages drain what is queued.
  void stop();
  // Waits until capture ended and every stage drained. Returns the first failure (source or
  // stage), ok otherwise.
  Status wait();
  LiveStatus status() const;

 private:
  struct StageState;
  void capture_loop();
  void stage_loop(size_t i);
  void fail(const Status& status);

  std::unique_ptr<FrameSource> source_;
  std::vector<LiveStage> specs_;
  LivePipelineOptions options_;
  std::vector<std::unique_ptr<StageState>> stages_;
  std::vector<std::thread> threads_;
  std::thread status_thread_;
  std::atomic<int> active_{0};
  std::atomic<bool> stop_requested_{false}, running_{false};
  std::atomic<int64_t> captured_{0};
  mutable std::mutex mutex_;  // guards failure_, source counters snapshot
  Status failure_;
  FrameSourceCounters source_counters_;
  std::chrono::steady_clock::time_point start_time_;
  std::chrono::steady_clock::time_point end_time_;
  bool started_ = false, joined_ = false;
};

}  // namespace gvkit
