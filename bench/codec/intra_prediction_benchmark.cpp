// Timings of the intra predictors (block-at-a-time vs the per-sample reference, and the quadratic
// mode) and of plane encoding (fast and slow presets) and decoding at 320x320, 16 bits.
#include <cmath>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "gvkit/codec/intra_prediction.hpp"
#include "gvkit/codec/plane_coding.hpp"
#include "gvkit/codec/quadratic_intra.hpp"

namespace gvkit::codec {
namespace {

IntraNeighbors random_neighbors() {
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> u(0, 65535);
  IntraNeighbors nb;
  nb.corner = u(rng);
  for (int& v : nb.top) v = u(rng);
  for (int& v : nb.left) v = u(rng);
  return nb;
}

void BM_Predict4x4AllModes(benchmark::State& state) {
  const IntraNeighbors nb = random_neighbors();
  int32_t out[16];
  const bool reference = state.range(0) != 0;
  for (auto _ : state)
    for (int mode = 0; mode < kIntra4x4ModeCount; ++mode) {
      if (reference)
        predict_intra_reference(4, mode, nb, 65535, out);
      else
        predict_intra(4, mode, nb, 65535, out);
      benchmark::DoNotOptimize(out);
    }
}
BENCHMARK(BM_Predict4x4AllModes)->Arg(0)->Arg(1)->ArgName("reference");

// The same thirteen predictions in one call (the fast preset's mode decision).
void BM_Predict4x4AllModesOneCall(benchmark::State& state) {
  const IntraNeighbors nb = random_neighbors();
  int32_t out[kIntra4x4ModeCount][16];
  for (auto _ : state) {
    predict_intra4x4_modes(nb, 65535, kIntra4x4ModeCount, out);
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_Predict4x4AllModesOneCall);

void BM_Predict16x16AllModes(benchmark::State& state) {
  const IntraNeighbors nb = random_neighbors();
  int32_t out[256];
  const bool reference = state.range(0) != 0;
  for (auto _ : state)
    for (int mode = 0; mode < kIntra16x16ModeCount; ++mode) {
      if (reference)
        predict_intra_reference(16, mode, nb, 65535, out);
      else
        predict_intra(16, mode, nb, 65535, out);
      benchmark::DoNotOptimize(out);
    }
}
BENCHMARK(BM_Predict16x16AllModes)->Arg(0)->Arg(1)->ArgName("reference");

// The quadratic 16x16 mode (format 1.13) on a smooth 16-bit plane with noise: the fit and the
// forward-difference evaluation, against the per-sample evaluation of the definition.
void BM_PredictQuadratic16(benchmark::State& state) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> noise(-40, 40);
  std::vector<uint16_t> plane(32 * 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x)
      plane[static_cast<size_t>(y) * 32 + x] =
          static_cast<uint16_t>(30000 + 9 * x * x - 5 * y * y + 7 * x * y + noise(rng));
  int32_t out[256];
  const bool reference = state.range(0) != 0;
  for (auto _ : state) {
    if (reference)
      predict_quadratic16_reference(plane.data(), 32, 8, 8, 65535, out);
    else
      predict_quadratic16(plane.data(), 32, 8, 8, 65535, out);
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_PredictQuadratic16)->Arg(0)->Arg(1)->ArgName("reference");

SamplePlane smooth_plane(int size) {
  SamplePlane p;
  p.width = p.height = size;
  p.samples.resize(static_cast<size_t>(size) * size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      p.at(x, y) = static_cast<uint16_t>(32768 + 20000 * std::sin(x * 0.02) * std::cos(y * 0.015));
  return p;
}

PlaneCodingParams params_for(int64_t preset) {
  PlaneCodingParams p;
  p.qp_prime = 36;
  p.rdo = preset != 0;
  p.allow_8x8 = preset != 0;
  return p;
}

void BM_EncodePlane320(benchmark::State& state) {
  const SamplePlane plane = smooth_plane(320);
  const PlaneCodingParams p = params_for(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(encode_plane(plane, p));
}
BENCHMARK(BM_EncodePlane320)->Arg(0)->Arg(1)->ArgName("slow")->Unit(benchmark::kMillisecond);

void BM_DecodePlane320(benchmark::State& state) {
  const SamplePlane plane = smooth_plane(320);
  const PlaneCodingParams p = params_for(0);
  const PlaneEncodeResult enc = encode_plane(plane, p);
  for (auto _ : state) benchmark::DoNotOptimize(decode_plane(enc.bytes, 320, 320, p));
}
BENCHMARK(BM_DecodePlane320)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gvkit::codec

BENCHMARK_MAIN();
