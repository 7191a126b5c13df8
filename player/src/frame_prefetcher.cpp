#include "gvkit/player/frame_prefetcher.hpp"

#include <algorithm>

namespace gvkit::player {

Status PrefetchOptions::check() const {
  if (ahead < 0) return invalid_argument("prefetch: ahead must be >= 0");
  if (capacity < ahead + 1) return invalid_argument("prefetch: capacity must be >= ahead + 1");
  return mesh.check();
}

FramePrefetcher::FramePrefetcher(std::shared_ptr<FrameSequence> sequence,
                                 const PrefetchOptions& options)
    : sequence_(std::move(sequence)), options_(options) {
  GVKIT_CHECK(sequence_ != nullptr, "no sequence");
  GVKIT_CHECK(options_.check().is_ok(), options_.check().message());
  frame_count_ = sequence_->frame_count();
  GVKIT_CHECK(frame_count_ >= 1, "empty sequence");
  worker_ = std::thread([this] { run(); });
}

FramePrefetcher::~FramePrefetcher() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  work_cv_.notify_all();
  worker_.join();
}

std::vector<int64_t> FramePrefetcher::window() const {
  std::vector<int64_t> w;
  for (int64_t k = 0; k <= options_.ahead && k < frame_count_; ++k) {
    int64_t i = target_ + k;
    if (i >= frame_count_) {
      if (!options_.loop) break;
      i -= frame_count_;
    }
    w.push_back(i);
  }
  return w;
}

void FramePrefetcher::evict() {
  if (cache_.size() <= static_cast<size_t>(options_.capacity)) return;
  // Drop the frames farthest ahead of the target (those just behind it come last in this order,
  // so they go first: playback moves forwards).
  std::vector<std::pair<int64_t, int64_t>> by_distance;  // (distance ahead, index)
  for (const auto& [index, frame] : cache_)
    by_distance.push_back(
        {((index - target_) % frame_count_ + frame_count_) % frame_count_, index});
  std::sort(by_distance.begin(), by_distance.end());
  while (cache_.size() > static_cast<size_t>(options_.capacity)) {
    cache_.erase(by_distance.back().second);
    by_distance.pop_back();
  }
}

void FramePrefetcher::run() {
  std::unique_lock lock(mutex_);
  while (!stop_) {
    int64_t next = -1;
    for (int64_t i : window())
      if (!cache_.count(i)) {
        next = i;
        break;
      }
    if (next < 0) {
      busy_ = false;
      done_cv_.notify_all();
      work_cv_.wait(lock);
      continue;
    }
    busy_ = true;
    lock.unlock();
    auto frame = std::make_shared<PreparedFrame>();
    frame->index = next;
    auto image = sequence_->frame(next);
    if (image.is_ok()) {
      frame->image = std::move(image).value();
      if (options_.build_mesh)
        frame->mesh = mesh_buffers_from_geometry_image(frame->image, options_.mesh);
    } else {
      frame->status = image.status();
    }
    lock.lock();
    cache_[next] = std::move(frame);
    evict();
    done_cv_.notify_all();
  }
}

std::shared_ptr<const PreparedFrame> FramePrefetcher::get(int64_t index) {
  GVKIT_CHECK(index >= 0 && index < frame_count_, "frame index out of range");
  std::unique_lock lock(mutex_);
  if (target_ != index) {
    target_ = index;
    work_cv_.notify_all();
  }
  auto it = cache_.find(index);
  if (it != cache_.end()) {
    ++hits_;
    return it->second;
  }
  ++misses_;
  work_cv_.notify_all();
  // The requested frame is first in the window, so the worker does it next (after the frame in
  // flight). A concurrent get() may move the target away; keep it pointing at ours meanwhile.
  done_cv_.wait(lock, [&] {
    if (target_ != index) {
      target_ = index;
      work_cv_.notify_all();
    }
    return cache_.count(index) > 0;
  });
  return cache_[index];
}

std::shared_ptr<const PreparedFrame> FramePrefetcher::try_get(int64_t index) {
  GVKIT_CHECK(index >= 0 && index < frame_count_, "frame index out of range");
  std::lock_guard lock(mutex_);
  target_ = index;
  work_cv_.notify_all();
  auto it = cache_.find(index);
  if (it == cache_.end()) {
    ++misses_;
    return nullptr;
  }
  ++hits_;
  return it->second;
}

void FramePrefetcher::wait_until_idle() {
  std::unique_lock lock(mutex_);
  work_cv_.notify_all();
  done_cv_.wait(lock, [&] {
    if (busy_) return false;
    for (int64_t i : window())
      if (!cache_.count(i)) return false;
    return true;
  });
}

void FramePrefetcher::set_loop(bool loop) {
  std::lock_guard lock(mutex_);
  options_.loop = loop;
  work_cv_.notify_all();
}

int64_t FramePrefetcher::hits() const {
  std::lock_guard lock(mutex_);
  return hits_;
}
int64_t FramePrefetcher::misses() const {
  std::lock_guard lock(mutex_);
  return misses_;
}
size_t FramePrefetcher::cached_count() const {
  std::lock_guard lock(mutex_);
  return cache_.size();
}

}  // namespace gvkit::player
