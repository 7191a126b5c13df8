#pragma once
// BoundedQueue: a thread-safe FIFO of at most `capacity` items between two pipeline stages. When
// full, push() blocks (back-pressure), evicts the oldest item, or rejects the new one, by policy;
// every evicted or rejected item is counted, never lost silently.

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>

#include "gvkit/core/status.hpp"

namespace gvkit {

enum class QueueFullPolicy {
  kBlock,       // the producer waits (back-pressure reaches the camera driver)
  kDropOldest,  // keep the freshest frames (live preview)
  kDropNewest,  // keep what is queued, reject the new item
};

// "block" | "drop-oldest" | "drop-newest".
const char* queue_full_policy_name(QueueFullPolicy policy);
Result<QueueFullPolicy> parse_queue_full_policy(const std::string& name);

template <typename T>
class BoundedQueue {
 public:
  BoundedQueue(size_t capacity, QueueFullPolicy policy) : capacity_(capacity), policy_(policy) {
    GVKIT_CHECK(capacity > 0, "a bounded queue needs capacity >= 1");
  }

  // Adds item (possibly evicting the oldest or rejecting item itself, both counted as dropped).
  // Returns false, dropping item uncounted, when the queue is closed.
  bool push(T item) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (policy_ == QueueFullPolicy::kBlock)
      not_full_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
    if (closed_) return false;
    if (items_.size() >= capacity_) {
      ++dropped_;
      if (policy_ == QueueFullPolicy::kDropNewest) return true;
      items_.pop_front();
    }
    items_.push_back(std::move(item));
    ++pushed_;
    if (items_.size() > max_depth_) max_depth_ = items_.size();
    lock.unlock();
    not_empty_.notify_one();
    return true;
  }

  // The oldest item; waits while empty. std::nullopt once closed and drained.
  std::optional<T> pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [&] { return closed_ || !items_.empty(); });
    if (items_.empty()) return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    lock.unlock();
    not_full_.notify_one();
    return item;
  }

  // No more pushes; pop() drains what is queued, then returns std::nullopt.
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    not_empty_.notify_all();
    not_full_.notify_all();
  }

  size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }
  size_t capacity() const { return capacity_; }
  size_t max_depth() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return max_depth_;
  }
  int64_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }
  int64_t pushed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return pushed_;
  }

 private:
  const size_t capacity_;
  const QueueFullPolicy policy_;
  mutable std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::deque<T> items_;
  bool closed_ = false;
  int64_t dropped_ = 0, pushed_ = 0;
  size_t max_depth_ = 0;
};

}  // namespace gvkit
