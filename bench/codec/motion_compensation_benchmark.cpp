// Timings of quarter-sample motion compensation of a 16x16 block, 16 bits, over all 16 phases:
// the block-wise interpolation (half-sample planes once per block) against the sample-by-sample
// reference.
#include <random>

#include <benchmark/benchmark.h>

#include "gvkit/codec/motion_compensation.hpp"

namespace gvkit::codec {
namespace {

void BM_PredictMotionBlock16x16AllPhases(benchmark::State& state) {
  SamplePlane ref;
  ref.width = ref.height = 64;
  ref.samples.resize(64 * 64);
  std::mt19937 rng(1);
  for (uint16_t& v : ref.samples) v = static_cast<uint16_t>(rng() & 0xffff);
  const bool reference = state.range(0) != 0;
  int32_t pred[256];
  for (auto _ : state)
    for (int phase = 0; phase < 16; ++phase) {
      const int mv_x = 20 + (phase & 3), mv_y = -12 + (phase >> 2);
      if (reference)
        predict_motion_block_reference(ref, 16, 16, 16, 16, mv_x, mv_y, true, 16, pred);
      else
        predict_motion_block(ref, 16, 16, 16, 16, mv_x, mv_y, true, 16, pred);
      benchmark::DoNotOptimize(pred);
    }
  state.SetItemsProcessed(state.iterations() * 16);
}
BENCHMARK(BM_PredictMotionBlock16x16AllPhases)->Arg(0)->Arg(1)->ArgName("reference");

}  // namespace
}  // namespace gvkit::codec

BENCHMARK_MAIN();
