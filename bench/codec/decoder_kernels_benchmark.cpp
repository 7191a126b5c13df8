// Timings of the decoder's optimised kernels against their plain references (the pairs that
// tests/codec/decoder_kernels_test.cpp checks for equality), on inputs shaped like a 320x320
// 16-bit geometry video's: Arg 0 = the optimised kernel (AVX2 where the processor has it), 1 =
// the reference.
//
//   build/bench/codec/codec_decoder_kernels_benchmark
#include <algorithm>
#include <array>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "gvkit/codec/cabac_decoder.hpp"
#include "gvkit/codec/cabac_encoder.hpp"
#include "gvkit/codec/deblocking.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/half_resolution.hpp"
#include "gvkit/codec/inverse_residual.hpp"
#include "gvkit/codec/motion_compensation.hpp"
#include "gvkit/codec/reconstruction_store.hpp"

namespace gvkit::codec {
namespace {

constexpr int kSize = 320;

// A smooth 16-bit plane with some noise (a geometry image's X, Y or Z).
SamplePlane smooth_plane(int width, int height, uint32_t seed) {
  SamplePlane p;
  p.width = width;
  p.height = height;
  p.samples.resize(static_cast<size_t>(width) * height);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> noise(-40, 40);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      p.at(x, y) = static_cast<uint16_t>(
          std::clamp(20000 + 90 * x + 40 * y + (x * y) % 700 + noise(rng), 0, 65535));
  return p;
}

bool reference(const benchmark::State& state) { return state.range(0) != 0; }

// Bins of a CABAC segment with skewed contexts (sixteen contexts, mostly MPS), as residual
// syntax has them.
void BM_CabacDecode(benchmark::State& state) {
  std::mt19937 rng(1);
  std::vector<int> bins(200000), which(bins.size());
  for (size_t i = 0; i < bins.size(); ++i) {
    which[i] = static_cast<int>(rng() % 16);
    bins[i] = static_cast<int>(rng() % 100) < 10 + 4 * which[i] ? 1 : 0;
  }
  CabacEncoder encoder;
  CabacContext contexts[16] = {};
  for (size_t i = 0; i < bins.size(); ++i) encoder.encode(contexts[which[i]], bins[i]);
  encoder.encode_terminate(1);
  const std::string data = encoder.finish();
  int sum = 0;
  for (auto _ : state) {
    CabacContext ctx[16] = {};
    if (reference(state)) {
      CabacDecoderReference decoder(data);
      for (size_t i = 0; i < bins.size(); ++i) sum += decoder.decode(ctx[which[i]]);
    } else {
      CabacDecoder decoder(data);
      for (size_t i = 0; i < bins.size(); ++i) sum += decoder.decode(ctx[which[i]]);
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(bins.size()));  // bins/s
}
BENCHMARK(BM_CabacDecode)->Arg(0)->Arg(1)->ArgName("reference");

// 16x16 level blocks as decoded at QP 12 (16-bit, qp' 60): a few low-frequency levels.
void BM_InverseResidual16x16Sparse(benchmark::State& state) {
  std::mt19937 rng(2);
  std::vector<std::array<int32_t, 256>> blocks(64);
  for (auto& b : blocks) {
    b.fill(0);
    for (int k = 0; k < 6; ++k)
      b[static_cast<size_t>((rng() % 4) * 16 + rng() % 4)] = (rng() % 9) - 4;
  }
  int32_t residual[256];
  size_t i = 0;
  for (auto _ : state) {
    const int32_t* levels = blocks[i++ % blocks.size()].data();
    if (reference(state))
      inverse_residual_reference(16, levels, 60, residual);
    else
      inverse_residual(16, levels, 60, residual);
    benchmark::DoNotOptimize(residual);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_InverseResidual16x16Sparse)->Arg(0)->Arg(1)->ArgName("reference");

// Every level nonzero (the worst case of the 32-bit path), at QP -18 (qp' 30).
void BM_InverseResidual16x16Dense(benchmark::State& state) {
  std::mt19937 rng(3);
  int32_t levels[256], residual[256];
  for (int32_t& v : levels) v = static_cast<int32_t>(rng() % 21) - 10;
  for (auto _ : state) {
    if (reference(state))
      inverse_residual_reference(16, levels, 30, residual);
    else
      inverse_residual(16, levels, 30, residual);
    benchmark::DoNotOptimize(residual);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_InverseResidual16x16Dense)->Arg(0)->Arg(1)->ArgName("reference");

// n x n level blocks (n = range(1): 4 or 8) at QP -10 (16-bit, qp' 38): n + n / 2 levels in the
// low-frequency quarter.
void BM_InverseResidualSmall(benchmark::State& state) {
  const int n = static_cast<int>(state.range(1));
  std::mt19937 rng(4);
  std::vector<std::array<int32_t, 64>> blocks(64);
  for (auto& b : blocks) {
    b.fill(0);
    for (int k = 0; k < n + n / 2; ++k)
      b[static_cast<size_t>((rng() % (n / 2)) * n + rng() % (n / 2))] =
          static_cast<int32_t>(rng() % 17) - 8;
  }
  int32_t residual[64];
  size_t i = 0;
  for (auto _ : state) {
    const int32_t* levels = blocks[i++ % blocks.size()].data();
    if (reference(state))
      inverse_residual_reference(n, levels, 38, residual);
    else
      inverse_residual(n, levels, 38, residual);
    benchmark::DoNotOptimize(residual);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_InverseResidualSmall)->ArgsProduct({{0, 1}, {4, 8}})->ArgNames({"reference", "n"});

// Quarter-sample prediction of a 16x16 block at every phase. The reference here is the plain
// block-wise path's own reference, sample by sample (motion_compensation_benchmark compares the
// two portable versions).
void BM_PredictMotionBlock16x16(benchmark::State& state) {
  const SamplePlane ref = smooth_plane(64, 64, 4);
  int32_t pred[256];
  for (auto _ : state)
    for (int phase = 1; phase < 16; ++phase) {
      const int mv_x = 20 + (phase & 3), mv_y = -12 + (phase >> 2);
      if (reference(state))
        predict_motion_block_reference(ref, 16, 16, 16, 16, mv_x, mv_y, true, 16, pred);
      else
        predict_motion_block(ref, 16, 16, 16, 16, mv_x, mv_y, true, 16, pred);
      benchmark::DoNotOptimize(pred);
    }
  state.SetItemsProcessed(state.iterations() * 15);
}
BENCHMARK(BM_PredictMotionBlock16x16)->Arg(0)->Arg(1)->ArgName("reference");

// Prediction + residual of a 16x16 macroblock into a plane.
void BM_StoreReconstruction16x16(benchmark::State& state) {
  std::mt19937 rng(5);
  int32_t pred[256], residual[256];
  for (int32_t& v : pred) v = 30000 + static_cast<int32_t>(rng() % 2000);
  for (int32_t& v : residual) v = static_cast<int32_t>(rng() % 200) - 100;
  SamplePlane plane = smooth_plane(kSize, kSize, 6);
  for (auto _ : state) {
    if (reference(state))
      store_reconstruction_reference(16, pred, 16, residual, 65535, plane.samples.data() + 16,
                                     kSize);
    else
      store_reconstruction(16, pred, 16, residual, 65535, plane.samples.data() + 16, kSize);
    benchmark::DoNotOptimize(plane.samples.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_StoreReconstruction16x16)->Arg(0)->Arg(1)->ArgName("reference");

// A 320x320 plane with every 8x8 grid edge at strength 1 or 2.
void BM_DeblockPlane(benchmark::State& state) {
  const SamplePlane source = smooth_plane(kSize, kSize, 7);
  DeblockingStrengths strengths;
  strengths.reset(kSize / 4, kSize / 4);
  for (size_t i = 0; i < strengths.vertical.size(); ++i) {
    strengths.vertical[i] = static_cast<uint8_t>(1 + i % 2);
    strengths.horizontal[i] = static_cast<uint8_t>(1 + (i / 7) % 2);
  }
  const DeblockingParams params;
  SamplePlane plane = source;
  for (auto _ : state) {
    state.PauseTiming();
    plane.samples = source.samples;
    state.ResumeTiming();
    if (reference(state))
      deblock_plane_reference(plane, strengths, 60, 16, params);
    else
      deblock_plane(plane, strengths, 60, 16, params);
    benchmark::DoNotOptimize(plane.samples.data());
  }
  state.SetItemsProcessed(state.iterations());  // planes/s
}
BENCHMARK(BM_DeblockPlane)->Arg(0)->Arg(1)->ArgName("reference");

// 160x160 (padded) -> 320x320, the decoder's half-resolution frames.
void BM_UpsampleHalfPlane(benchmark::State& state) {
  const SamplePlane half = smooth_plane(160, 160, 8);
  for (auto _ : state) {
    const SamplePlane full = reference(state)
                                 ? upsample_half_plane_reference(half, kSize, kSize, 16)
                                 : upsample_half_plane(half, kSize, kSize, 16);
    benchmark::DoNotOptimize(full.samples.data());
  }
  state.SetItemsProcessed(state.iterations());  // planes/s
}
BENCHMARK(BM_UpsampleHalfPlane)->Arg(0)->Arg(1)->ArgName("reference");

// Three 16-bit planes -> a 320x320 geometry image in millimetres.
void BM_DequantizeGeometry(benchmark::State& state) {
  SequenceInfo info;
  info.width = info.height = kSize;
  info.box_min_mm = cv::Vec3d(-70, -110, 610);
  info.box_max_mm = cv::Vec3d(75, 90, 715);
  info.domain_mask = cv::Mat(kSize, kSize, CV_8U, cv::Scalar(255));
  const std::vector<SamplePlane> planes = {smooth_plane(kSize, kSize, 9),
                                           smooth_plane(kSize, kSize, 10),
                                           smooth_plane(kSize, kSize, 11)};
  for (auto _ : state) {
    const GeometryImage image = reference(state) ? dequantize_geometry_reference(planes, info, 0)
                                                 : dequantize_geometry(planes, info, 0);
    benchmark::DoNotOptimize(image.xyz_mm.data);
  }
  state.SetItemsProcessed(state.iterations());  // frames/s
}
BENCHMARK(BM_DequantizeGeometry)->Arg(0)->Arg(1)->ArgName("reference");

}  // namespace
}  // namespace gvkit::codec

BENCHMARK_MAIN();
