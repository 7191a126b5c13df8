#pragma once
// FramePrefetcher: decodes a FrameSequence ahead of playback on one worker thread into a bounded
// cache, and builds each frame's mesh there too, so the drawing thread only uploads buffers.
// All decoding happens on the worker (FrameSequence is single-threaded); get() of a frame that
// is not cached makes it the worker's next job and waits for it (a seek).

#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "gvkit/player/frame_sequence.hpp"
#include "gvkit/player/geometry_image_mesh.hpp"

namespace gvkit::player {

struct PrefetchOptions {
  int ahead = 8;      // frames decoded after the requested one
  int capacity = 16;  // most frames kept; >= ahead + 1
  bool loop = true;   // look ahead past the end into frame 0, 1, ...
  bool build_mesh = true;
  GeometryImageMeshOptions mesh;
  Status check() const;
};

// One decoded frame: status ok with image (and mesh when built), or the failure that names it.
struct PreparedFrame {
  int64_t index = 0;
  Status status;
  GeometryImage image;
  MeshBuffers mesh;
};

class FramePrefetcher {
 public:
  // sequence is shared with the caller, who must not call its frame() while this object lives.
  // options must pass check() (contract).
  FramePrefetcher(std::shared_ptr<FrameSequence> sequence, const PrefetchOptions& options = {});
  ~FramePrefetcher();  // stops and joins the worker
  FramePrefetcher(const FramePrefetcher&) = delete;
  FramePrefetcher& operator=(const FramePrefetcher&) = delete;

  // The frame, waiting for it if needed; moves the look-ahead window to start at index.
  // 0 <= index < frame_count (contract).
  std::shared_ptr<const PreparedFrame> get(int64_t index);
  // The frame if cached, else nullptr; either way moves the look-ahead window to index.
  std::shared_ptr<const PreparedFrame> try_get(int64_t index);
  // Blocks until the worker has filled the current look-ahead window (for tests, benchmarks).
  void wait_until_idle();

  void set_loop(bool loop);
  int64_t hits() const;    // get/try_get calls answered from the cache
  int64_t misses() const;  // calls that had to wait for (or found no) frame
  size_t cached_count() const;
  FrameSequence& sequence() { return *sequence_; }

 private:
  void run();
  // Indices of the look-ahead window, nearest first. Caller holds mutex_.
  std::vector<int64_t> window() const;
  void evict();  // caller holds mutex_

  std::shared_ptr<FrameSequence> sequence_;
  PrefetchOptions options_;
  int64_t frame_count_;
  mutable std::mutex mutex_;
  std::condition_variable work_cv_, done_cv_;
  std::map<int64_t, std::shared_ptr<const PreparedFrame>> cache_;
  int64_t target_ = 0;
  bool stop_ = false, busy_ = false;
  int64_t hits_ = 0, misses_ = 0;
  std::thread worker_;
};

}  // namespace gvkit::player
