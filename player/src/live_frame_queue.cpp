#include "gvkit/player/live_frame_queue.hpp"

#include "gvkit/player/geometry_image_mesh.hpp"

namespace gvkit::player {

LiveFrameQueue::LiveFrameQueue(size_t capacity) : capacity_(capacity) {
  GVKIT_CHECK(capacity >= 1, "live queue capacity must be >= 1");
}

void LiveFrameQueue::push(GeometryImage frame) {
  GVKIT_CHECK(frame.check().is_ok(), frame.check().message());
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    if (pending_.size() >= capacity_) {
      pending_.pop_front();
      ++dropped_;
    }
    pending_.push_back(std::move(frame));
    ++pushed_;
  }
  cv_.notify_all();
}

Status LiveFrameQueue::push(const RangeScan& scan) {
  GVKIT_ASSIGN_OR_RETURN(GeometryImage image, geometry_image_from_range_scan(scan));
  push(std::move(image));
  return Status::ok();
}

void LiveFrameQueue::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  cv_.notify_all();
}

std::optional<GeometryImage> LiveFrameQueue::take_latest() {
  std::lock_guard lock(mutex_);
  if (pending_.empty()) return std::nullopt;
  dropped_ += static_cast<int64_t>(pending_.size()) - 1;
  GeometryImage latest = std::move(pending_.back());
  pending_.clear();
  return latest;
}

std::optional<GeometryImage> LiveFrameQueue::wait_latest(std::chrono::milliseconds timeout) {
  {
    std::unique_lock lock(mutex_);
    cv_.wait_for(lock, timeout, [&] { return !pending_.empty() || closed_; });
  }
  return take_latest();
}

bool LiveFrameQueue::closed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}
int64_t LiveFrameQueue::pushed() const {
  std::lock_guard lock(mutex_);
  return pushed_;
}
size_t LiveFrameQueue::pending() const {
  std::lock_guard lock(mutex_);
  return pending_.size();
}
int64_t LiveFrameQueue::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

}  // namespace gvkit::player
