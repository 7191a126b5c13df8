// Per-set cost of each step of `gvkit capture --source file:SESSION [--reconstruct]`, on the
// sets of a recorded session (set GVKIT_BENCH_SESSION to its folder, e.g. one made by
// `gvkit synth -o S --frames 60 --size 512x512`):
//   read     the replay source: one set's PNGs decoded (SessionReader::read_frame)
//   append   the record stage: one set's PNGs written crash-safely + session.json (SessionWriter)
//   reconstruct  the reconstruct stage's kernel (Reconstructor::reconstruct)
//   truth    the live error of a replay: gt/ EXR read + scan_accuracy (not part of a live camera
//            capture; skipped with --no-ground-truth)
// Wall time per set (UseRealTime); the CPU column shows what the two cores spend.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <optional>

#include "gvkit/capture/ground_truth.hpp"
#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/reconstructor.hpp"
#include "gvkit/capture/scan_accuracy.hpp"
#include "gvkit/capture/session_reader.hpp"
#include "gvkit/capture/session_writer.hpp"

namespace gvkit {
namespace {
namespace fs = std::filesystem;

const capture::SessionReader* session() {
  static std::optional<capture::SessionReader> reader = []() {
    std::optional<capture::SessionReader> r;
    if (const char* dir = std::getenv("GVKIT_BENCH_SESSION")) {
      auto opened = capture::SessionReader::open(dir);
      if (opened.is_ok()) r.emplace(std::move(*opened));
    }
    return r;
  }();
  return reader ? &*reader : nullptr;
}

#define NEED_SESSION(state)                    \
  const capture::SessionReader* s = session(); \
  if (!s || s->frame_count() == 0)             \
    return (state).SkipWithError("set GVKIT_BENCH_SESSION to a recorded session folder");

void BM_ReadSet(benchmark::State& state) {
  NEED_SESSION(state);
  size_t i = 0;
  for (auto _ : state) {
    auto set = s->read_frame(i++ % s->frame_count());
    if (!set.is_ok()) return state.SkipWithError(set.status().message().c_str());
    benchmark::DoNotOptimize(set->images.data());
  }
}
BENCHMARK(BM_ReadSet)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_AppendSet(benchmark::State& state) {
  NEED_SESSION(state);
  const fs::path dir = fs::temp_directory_path() / "gvkit-bench-append";
  fs::remove_all(dir);
  capture::SessionInfo info = s->info();
  info.ground_truth_dir.clear();
  auto writer = capture::SessionWriter::create(dir, info, s->calibration());
  if (!writer.is_ok()) return state.SkipWithError(writer.status().message().c_str());
  std::vector<FringeSet> sets;
  for (size_t i = 0; i < std::min<size_t>(s->frame_count(), 10); ++i)
    sets.push_back(s->read_frame(i).value());
  int64_t index = 0;
  for (auto _ : state) {
    FringeSet set = sets[static_cast<size_t>(index) % sets.size()];
    set.index = index++;
    const Status written = (*writer)->append(set);
    if (!written.is_ok()) return state.SkipWithError(written.message().c_str());
  }
  writer->reset();
  fs::remove_all(dir);
}
BENCHMARK(BM_AppendSet)->Unit(benchmark::kMillisecond)->Iterations(60)->UseRealTime();

void BM_ReconstructSet(benchmark::State& state) {
  NEED_SESSION(state);
  auto patterns = capture::create_pattern_set(s->info().pattern);
  auto reconstructor = capture::Reconstructor::create(s->calibration());
  if (!patterns.is_ok() || !reconstructor.is_ok())
    return state.SkipWithError("pattern or calibration of the session not usable");
  const FringeSet set = s->read_frame(0).value();
  for (auto _ : state) {
    auto scan = reconstructor->reconstruct(set, **patterns);
    if (!scan.is_ok()) return state.SkipWithError(scan.status().message().c_str());
    benchmark::DoNotOptimize(scan->xyz_mm.data);
  }
}
BENCHMARK(BM_ReconstructSet)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_TruthReadAndError(benchmark::State& state) {
  NEED_SESSION(state);
  auto path = s->ground_truth_path(s->info().frames.front().index);
  if (!path) return state.SkipWithError("the session has no gt/");
  auto patterns = capture::create_pattern_set(s->info().pattern);
  auto reconstructor = capture::Reconstructor::create(s->calibration());
  if (!patterns.is_ok() || !reconstructor.is_ok())
    return state.SkipWithError("pattern or calibration of the session not usable");
  const RangeScan scan = reconstructor->reconstruct(s->read_frame(0).value(), **patterns).value();
  for (auto _ : state) {
    auto truth = capture::read_ground_truth_exr(*path);
    if (!truth.is_ok()) return state.SkipWithError(truth.status().message().c_str());
    benchmark::DoNotOptimize(capture::scan_accuracy(scan, *truth).rms_mm);
  }
}
BENCHMARK(BM_TruthReadAndError)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace gvkit

BENCHMARK_MAIN();
