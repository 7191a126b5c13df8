#include "gvkit/capture/live_pipeline.hpp"

#include <cmath>
#include <cstdio>

namespace gvkit {

const char* queue_full_policy_name(QueueFullPolicy policy) {
  switch (policy) {
    case QueueFullPolicy::kBlock:
      return "block";
    case QueueFullPolicy::kDropOldest:
      return "drop-oldest";
    case QueueFullPolicy::kDropNewest:
      return "drop-newest";
  }
  return "?";
}

Result<QueueFullPolicy> parse_queue_full_policy(const std::string& name) {
  for (QueueFullPolicy p :
       {QueueFullPolicy::kBlock, QueueFullPolicy::kDropOldest, QueueFullPolicy::kDropNewest})
    if (name == queue_full_policy_name(p)) return p;
  return invalid_argument("queue policy '" + name +
                          "' is not one of block, drop-oldest, drop-newest");
}

Status LivePipelineOptions::check() const {
  if (max_frames < 0) return invalid_argument("live pipeline: max_frames is negative");
  if (!(max_seconds >= 0) || !std::isfinite(max_seconds))
    return invalid_argument("live pipeline: max_seconds must be >= 0");
  if (!(status_interval_s >= 0) || !std::isfinite(status_interval_s))
    return invalid_argument("live pipeline: status_interval_s must be >= 0");
  return Status::ok();
}

std::string LiveStatus::line() const {
  char text[512];
  const double seconds = elapsed_s > 0 ? elapsed_s : 1e-9;
  std::snprintf(text, sizeof(text), "%.1f s | in %.1f fps", elapsed_s,
                static_cast<double>(captured) / seconds);
  std::string out = text;
  for (const LiveStageStatus& s : stages) {
    std::snprintf(text, sizeof(text),
                  " | %s: out %.1f fps q %zu/%zu (max %zu) drop %lld lat %.1f ms (max %.1f)",
                  s.name.c_str(), static_cast<double>(s.out) / seconds, s.queue_depth,
                  s.queue_capacity, s.max_queue_depth, static_cast<long long>(s.dropped),
                  s.latency_mean_ms, s.latency_max_ms);
    out += text;
  }
  std::snprintf(text, sizeof(text), " | source drop %lld err %lld",
                static_cast<long long>(source.dropped), static_cast<long long>(source.errored));
  return out + text;
}

struct LivePipeline::StageState {
  std::unique_ptr<BoundedQueue<LivePacket>> queue;
  std::atomic<int64_t> in{0}, out{0};
  mutable std::mutex mutex;
  double latency_sum_ms = 0, latency_max_ms = 0;
};

LivePipeline::LivePipeline(std::unique_ptr<FrameSource> source, std::vector<LiveStage> stages,
                           LivePipelineOptions options)
    : source_(std::move(source)), specs_(std::move(stages)), options_(std::move(options)) {
  GVKIT_CHECK(source_ != nullptr, "live pipeline without a source");
  for (const LiveStage& spec : specs_) {
    GVKIT_CHECK(spec.run != nullptr, "live stage '" + spec.name + "' has no function");
    auto state = std::make_unique<StageState>();
    state->queue = std::make_unique<BoundedQueue<LivePacket>>(spec.queue_capacity, spec.when_full);
    stages_.push_back(std::move(state));
  }
}

LivePipeline::~LivePipeline() {
  if (started_ && !joined_) {
    stop();
    (void)wait();
  }
}

Status LivePipeline::start() {
  GVKIT_CHECK(!started_, "live pipeline started twice");
  GVKIT_RETURN_IF_ERROR(options_.check());
  started_ = true;
  running_ = true;
  start_time_ = std::chrono::steady_clock::now();
  active_ = static_cast<int>(stages_.size()) + 1;
  threads_.emplace_back([this] { capture_loop(); });
  for (size_t i = 0; i < stages_.size(); ++i) threads_.emplace_back([this, i] { stage_loop(i); });
  if (options_.on_status && options_.status_interval_s > 0)
    status_thread_ = std::thread([this] {
      const auto interval = std::chrono::duration<double>(options_.status_interval_s);
      auto next = std::chrono::steady_clock::now() + interval;
      while (active_ > 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        if (std::chrono::steady_clock::now() >= next && active_ > 0) {
          options_.on_status(status());
          next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(interval);
        }
      }
    });
  return Status::ok();
}

void LivePipeline::stop() { stop_requested_ = true; }

void LivePipeline::fail(const Status& status) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (failure_.is_ok()) failure_ = status;
  }
  stop_requested_ = true;
  for (auto& s : stages_) s->queue->close();
}

void LivePipeline::capture_loop() {
  const auto limit = std::chrono::duration<double>(options_.max_seconds);
  while (!stop_requested_) {
    if (options_.max_frames > 0 && captured_ >= options_.max_frames) break;
    if (options_.max_seconds > 0 && std::chrono::steady_clock::now() - start_time_ >= limit) break;
    Result<std::optional<CameraFrame>> frame = source_->next();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      source_counters_ = source_->counters();
    }
    if (!frame.is_ok()) {
      fail(frame.status());
      break;
    }
    if (!frame->has_value()) break;
    LivePacket packet;
    packet.index = captured_;
    packet.arrived = monotonic_now();
    packet.value = std::move(**frame);
    ++captured_;
    if (!stages_.empty() && !stages_.front()->queue->push(std::move(packet))) break;
  }
  if (!stages_.empty()) stages_.front()->queue->close();
  --active_;
}

void LivePipeline::stage_loop(size_t i) {
  StageState& stage = *stages_[i];
  const std::string& name = specs_[i].name;
  while (std::optional<LivePacket> packet = stage.queue->pop()) {
    ++stage.in;
    Result<std::optional<std::any>> result = specs_[i].run(std::move(packet->value));
    if (!result.is_ok()) {
      fail(result.status().with_context(name));
      break;
    }
    if (!result->has_value()) continue;
    const double latency_ms =
        std::chrono::duration<double, std::milli>(monotonic_now() - packet->arrived).count();
    {
      std::lock_guard<std::mutex> lock(stage.mutex);
      stage.latency_sum_ms += latency_ms;
      stage.latency_max_ms = std::max(stage.latency_max_ms, latency_ms);
    }
    ++stage.out;
    if (i + 1 < stages_.size()) {
      LivePacket next{packet->index, packet->arrived, std::move(**result)};
      if (!stages_[i + 1]->queue->push(std::move(next))) break;
    }
  }
  if (i + 1 < stages_.size()) stages_[i + 1]->queue->close();
  --active_;
}

Status LivePipeline::wait() {
  GVKIT_CHECK(started_, "wait() before start()");
  if (!joined_) {
    for (auto& t : threads_) t.join();
    end_time_ = std::chrono::steady_clock::now();
    running_ = false;
    if (status_thread_.joinable()) status_thread_.join();
    joined_ = true;
    if (options_.on_status) options_.on_status(status());
  }
  std::lock_guard<std::mutex> lock(mutex_);
  return failure_;
}

LiveStatus LivePipeline::status() const {
  LiveStatus s;
  const auto now = running_ ? std::chrono::steady_clock::now() : end_time_;
  s.elapsed_s = started_ ? std::chrono::duration<double>(now - start_time_).count() : 0;
  s.captured = captured_;
  s.running = running_;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    s.source = source_counters_;
  }
  for (size_t i = 0; i < stages_.size(); ++i) {
    const StageState& stage = *stages_[i];
    LiveStageStatus st;
    st.name = specs_[i].name;
    st.in = stage.in;
    st.out = stage.out;
    st.dropped = stage.queue->dropped();
    st.queue_depth = stage.queue->size();
    st.queue_capacity = stage.queue->capacity();
    st.max_queue_depth = stage.queue->max_depth();
    {
      std::lock_guard<std::mutex> lock(stage.mutex);
      st.latency_mean_ms = st.out > 0 ? stage.latency_sum_ms / static_cast<double>(st.out) : 0;
      st.latency_max_ms = stage.latency_max_ms;
    }
    s.stages.push_back(std::move(st));
  }
  return s;
}

}  // namespace gvkit
