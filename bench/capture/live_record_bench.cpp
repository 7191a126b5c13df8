// Live capture figures on this machine: the crash-safe recorder's frame rate, and a paced
// 30 fps stream of 512x512 3-step fringe images through the live pipeline into the recorder
// (drops and latency). The frames are plain sinusoidal fringes (16 periods), not a rendered
// face: this measures the capture/record path, not reconstruction.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <random>

#include "gvkit/capture/callback_frame_source.hpp"
#include "gvkit/capture/frame_recorder.hpp"
#include "gvkit/capture/live_pipeline.hpp"

namespace gvkit {
namespace {
namespace fs = std::filesystem;

// Fringe k of a 3-step set (phase 2*pi*k/3), with mild noise so PNG does not compress it away.
cv::Mat fringe(int64_t index, int size = 512) {
  const int k = static_cast<int>(index % 3);
  cv::Mat image(size, size, CV_8U);
  std::mt19937 rng(static_cast<uint32_t>(index));
  std::uniform_int_distribution<int> noise(-2, 2);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double phase = 2 * M_PI * 16.0 * x / size + 2 * M_PI * k / 3.0;
      const int v = static_cast<int>(128 + 90 * std::cos(phase)) + noise(rng);
      image.at<uint8_t>(y, x) = static_cast<uint8_t>(std::clamp(v, 0, 255));
    }
  return image;
}

fs::path fresh_dir(const char* name) {
  const fs::path dir = fs::temp_directory_path() / name;
  fs::remove_all(dir);
  return dir;
}

void BM_RecorderAppend512(benchmark::State& state) {
  const fs::path dir = fresh_dir("gvkit-bench-recorder");
  FrameRecorderOptions o;
  o.min_free_bytes = 0;
  auto recorder = FrameRecorder::create(dir, o);
  if (!recorder.is_ok()) return state.SkipWithError(recorder.status().message().c_str());
  std::vector<cv::Mat> frames = {fringe(0), fringe(1), fringe(2)};
  int64_t i = 0;
  for (auto _ : state) {
    CameraFrame f;
    f.image = frames[static_cast<size_t>(i % 3)];
    f.sequence = i++;
    const Status s = (*recorder)->append(f);
    if (!s.is_ok()) return state.SkipWithError(s.message().c_str());
  }
  state.SetItemsProcessed(state.iterations());
  recorder->reset();
  fs::remove_all(dir);
}
BENCHMARK(BM_RecorderAppend512)->Unit(benchmark::kMillisecond)->Iterations(150)->UseRealTime();

void BM_Live30fpsRecord512(benchmark::State& state) {
  const int64_t frames = state.range(0);
  for (auto _ : state) {
    const fs::path dir = fresh_dir("gvkit-bench-live");
    FrameRecorderOptions ro;
    ro.min_free_bytes = 0;
    std::shared_ptr<FrameRecorder> recorder(FrameRecorder::create(dir, ro).value().release());
    FrameSourceOptions so;
    so.fps = 30;
    so.paced = true;
    so.frame_count = frames;
    auto source = make_callback_source([](int64_t i) -> Result<cv::Mat> { return fringe(i); }, so,
                                       "synthetic:fringes");
    LiveStage record;
    record.name = "record";
    record.queue_capacity = 8;
    record.when_full = QueueFullPolicy::kDropOldest;
    record.run = [recorder](std::any&& v) -> Result<std::optional<std::any>> {
      GVKIT_RETURN_IF_ERROR(recorder->append(std::any_cast<const CameraFrame&>(v)));
      return std::optional<std::any>(std::any());
    };
    LivePipeline pipeline(std::move(source), {record}, {});
    if (!pipeline.start().is_ok()) return state.SkipWithError("start failed");
    const Status s = pipeline.wait();
    if (!s.is_ok()) return state.SkipWithError(s.message().c_str());
    const LiveStatus st = pipeline.status();
    state.counters["captured"] = static_cast<double>(st.captured);
    state.counters["recorded"] = static_cast<double>(recorder->frames_written());
    state.counters["dropped"] = static_cast<double>(st.stages[0].dropped);
    state.counters["fps_in"] = static_cast<double>(st.captured) / st.elapsed_s;
    state.counters["lat_mean_ms"] = st.stages[0].latency_mean_ms;
    state.counters["lat_max_ms"] = st.stages[0].latency_max_ms;
    state.counters["max_queue"] = static_cast<double>(st.stages[0].max_queue_depth);
    fs::remove_all(dir);
  }
}
BENCHMARK(BM_Live30fpsRecord512)->Arg(300)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
}  // namespace gvkit

BENCHMARK_MAIN();
