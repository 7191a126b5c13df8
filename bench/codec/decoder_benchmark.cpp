// Decoding speed of a whole .gvid stream (Google Benchmark): every frame in display order, as a
// player reads it, including the conversion to millimetres (GeometryImage). The stream is the
// file named by GVKIT_BENCH_STREAM (e.g. one written by `gvkit encode`); without it the
// benchmark reports an error and runs nothing.
//
//   GVKIT_BENCH_STREAM=face.gvid build/bench/codec/codec_decoder_benchmark
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>

#include "gvkit/codec/gvid_reader.hpp"

namespace gvkit::codec {
namespace {

void BM_DecodeStream(benchmark::State& state) {
  const char* path = std::getenv("GVKIT_BENCH_STREAM");
  if (!path) {
    state.SkipWithError("set GVKIT_BENCH_STREAM to a .gvid file");
    return;
  }
  auto opened = GvidReader::open(path);
  if (!opened.is_ok()) {
    state.SkipWithError(opened.status().message().c_str());
    return;
  }
  const std::unique_ptr<GvidReader> probe = std::move(opened).value();
  const int64_t frames = probe->frame_count();
  for (auto _ : state) {
    // A fresh reader each time, so that no decoded anchor is reused from the last iteration.
    state.PauseTiming();
    std::unique_ptr<GvidReader> reader = GvidReader::open(path).value();
    state.ResumeTiming();
    for (int64_t f = 0; f < frames; ++f) {
      auto frame = reader->decode_frame(f);
      if (!frame.is_ok()) {
        state.SkipWithError(frame.status().message().c_str());
        return;
      }
      benchmark::DoNotOptimize(frame.value().xyz_mm.data);
    }
  }
  state.SetItemsProcessed(state.iterations() * frames);  // items/s = frames per second
}
BENCHMARK(BM_DecodeStream)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

}  // namespace
}  // namespace gvkit::codec

BENCHMARK_MAIN();
