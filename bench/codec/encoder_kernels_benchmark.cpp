// Timings of the encoder's kernels against their plain reference versions: SAD of two 16x16
// blocks, SATD of a 16x16 and a 4x4 block against a prediction, 4x4 quantization, a block's
// quantization with fixed offsets against the rate-distortion optimised one, and the
// quarter-sample prediction of a 16x16 block (all 16 phases) from the precomputed half-sample
// planes against the block-wise interpolation, the sub-sample search's SATD from those planes
// against that of the formed prediction; plus building those planes for a 320x320 plane,
// and a 320x320 geometry image's quantization into its coded planes (quantize_geometry).
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

#include "forward_transform16x16_simd.hpp"
#include "gvkit/codec/block_distortion.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/motion_compensation.hpp"
#include "gvkit/codec/transform.hpp"
#include "gvkit/codec/transform16x16.hpp"
#include "rdo_quantization.hpp"

namespace gvkit::codec {
namespace {

SamplePlane random_plane(int size) {
  SamplePlane p;
  p.width = p.height = size;
  p.samples.resize(static_cast<size_t>(size) * size);
  std::mt19937 rng(1);
  for (uint16_t& v : p.samples) v = static_cast<uint16_t>(rng() & 0xffff);
  return p;
}

void BM_Sad16x16(benchmark::State& state) {
  const SamplePlane p = random_plane(64);
  const bool reference = state.range(0) != 0;
  const uint16_t* a = &p.samples[5 * 64 + 3];
  const uint16_t* b = &p.samples[20 * 64 + 30];
  for (auto _ : state)
    benchmark::DoNotOptimize(reference ? sad16x16_reference(a, 64, b, 64) : sad16x16(a, 64, b, 64));
}
BENCHMARK(BM_Sad16x16)->Arg(0)->Arg(1)->ArgName("reference");

void BM_Satd(benchmark::State& state) {
  const SamplePlane p = random_plane(64);
  const int n = static_cast<int>(state.range(0));
  const bool reference = state.range(1) != 0;
  int32_t pred[256];
  for (int i = 0; i < 256; ++i) pred[i] = p.samples[40 * 64 + i];
  const uint16_t* src = &p.samples[5 * 64 + 3];
  for (auto _ : state)
    benchmark::DoNotOptimize(reference ? satd_block_reference(n, src, 64, pred)
                                       : satd_block(n, src, 64, pred));
}
BENCHMARK(BM_Satd)->ArgsProduct({{4, 16}, {0, 1}})->ArgNames({"n", "reference"});

// The fast preset's mode decision: SATD of one 4x4 block against 13 predictions.
void BM_Satd4x4ThirteenPredictions(benchmark::State& state) {
  const SamplePlane p = random_plane(64);
  const bool reference = state.range(0) != 0;
  int32_t preds[13][16];
  for (int m = 0; m < 13; ++m)
    for (int i = 0; i < 16; ++i) preds[m][i] = p.samples[30 * 64 + m * 16 + i];
  const uint16_t* src = &p.samples[5 * 64 + 3];
  int64_t out[13];
  for (auto _ : state) {
    if (reference)
      for (int m = 0; m < 13; ++m) out[m] = satd_block_reference(4, src, 64, preds[m]);
    else
      distortions4x4(false, src, 64, preds, 13, out);
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_Satd4x4ThirteenPredictions)->Arg(0)->Arg(1)->ArgName("reference");

void BM_Quantize4x4(benchmark::State& state) {
  int32_t coeffs[16], levels[16];
  std::mt19937 rng(2);
  for (int32_t& c : coeffs) c = static_cast<int32_t>(rng() % 200000) - 100000;
  const bool reference = state.range(0) != 0;
  for (auto _ : state) {
    if (reference)
      quantize_reference(4, coeffs, 48, levels);
    else
      quantize(4, coeffs, 48, levels);
    benchmark::DoNotOptimize(levels);
  }
}
BENCHMARK(BM_Quantize4x4)->Arg(0)->Arg(1)->ArgName("reference");

// One block's quantization, fixed offset (method 0) against rate-distortion optimised (1), on
// the transform of a residual of Laplacian noise of two quantizer steps at QP' 48 (QP 0 of a
// 16-bit plane), where about a third of the levels are nonzero.
void BM_QuantizeBlock(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const bool rdo = state.range(1) != 0;
  const int qp = 48;
  std::mt19937 rng(3);
  std::exponential_distribution<double> e(1.0 / (2.0 * quantizer_step(qp)));
  int32_t residual[256], coeffs[256], levels[256];
  for (int i = 0; i < n * n; ++i) residual[i] = static_cast<int32_t>((rng() & 1 ? 1 : -1) * e(rng));
  forward_transform(n, residual, coeffs);
  const detail::ContextSet ctx{};
  const double lambda = 0.85 * std::pow(2.0, (qp - 12) / 3.0);
  for (auto _ : state) {
    if (rdo)
      detail::quantize_rdo(n, coeffs, qp, lambda, ctx, levels);
    else if (n == 16)
      quantize16x16(coeffs, qp, false, levels);
    else
      quantize(n, coeffs, qp, levels);
    benchmark::DoNotOptimize(levels);
  }
}
BENCHMARK(BM_QuantizeBlock)->ArgsProduct({{4, 8, 16}, {0, 1}})->ArgNames({"n", "rdo"});

// The 16x16 forward transform of a residual within the 32-bit range: the int64 butterfly
// (method 0, the only path before the 32-bit one), the portable 32-bit version (1), the AVX2
// one (2), and the matrix-product reference (3).
void BM_ForwardTransform16x16(benchmark::State& state) {
  const int method = static_cast<int>(state.range(0));
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> u(-3000, 3000);
  int32_t residual[256], coeffs[256];
  for (int32_t& v : residual) v = u(rng);
  for (auto _ : state) {
    if (method == 0)
      forward_transform16x16_butterfly64(residual, coeffs);
    else if (method == 1)
      detail::forward_transform16x16_32(residual, coeffs);
    else if (method == 2)
      detail::forward_transform16x16_32_avx2(residual, coeffs);
    else
      forward_transform16x16_reference(residual, coeffs);
    benchmark::DoNotOptimize(coeffs);
  }
}
BENCHMARK(BM_ForwardTransform16x16)->DenseRange(0, 3)->ArgName("method");

void BM_QuarterSample16x16AllPhases(benchmark::State& state) {
  const SamplePlane ref = random_plane(64);
  const InterpolatedReference interp(ref, 16, 12);
  const bool block_wise = state.range(0) != 0;
  int32_t pred[256];
  for (auto _ : state)
    for (int phase = 0; phase < 16; ++phase) {
      const int mv_x = 20 + (phase & 3), mv_y = -12 + (phase >> 2);
      if (block_wise)
        predict_motion_block(ref, 16, 16, 16, 16, mv_x, mv_y, true, 16, pred);
      else
        interp.predict(16, 16, 16, 16, mv_x, mv_y, true, pred);
      benchmark::DoNotOptimize(pred);
    }
  state.SetItemsProcessed(state.iterations() * 16);
}
BENCHMARK(BM_QuarterSample16x16AllPhases)->Arg(0)->Arg(1)->ArgName("block_wise");

// The sub-sample motion search's cost of a 16x16 block at each of the 16 phases: SATD straight
// from the stored half-sample rows (satd_block_of_average) against forming the prediction and
// taking its SATD, as the search did before.
void BM_SubsampleSatd16x16AllPhases(benchmark::State& state) {
  const SamplePlane ref = random_plane(64), src = random_plane(64);
  const InterpolatedReference interp(ref, 16, 12);
  const bool formed = state.range(0) != 0;
  const uint16_t* block = &src.samples[16 * 64 + 16];
  int32_t pred[256];
  for (auto _ : state)
    for (int phase = 0; phase < 16; ++phase) {
      const int mv_x = 20 + (phase & 3), mv_y = -12 + (phase >> 2);
      const uint16_t *first = nullptr, *second = nullptr;
      if (formed || !interp.quarter_block_rows(16, 16, 16, 16, mv_x, mv_y, &first, &second)) {
        interp.predict(16, 16, 16, 16, mv_x, mv_y, true, pred);
        benchmark::DoNotOptimize(satd_block(16, block, 64, pred));
      } else {
        benchmark::DoNotOptimize(
            satd_block_of_average(16, block, 64, first, second, interp.stride()));
      }
    }
  state.SetItemsProcessed(state.iterations() * 16);
}
BENCHMARK(BM_SubsampleSatd16x16AllPhases)->Arg(0)->Arg(1)->ArgName("formed");

void BM_InterpolatedReference320(benchmark::State& state) {
  const SamplePlane ref = random_plane(320);
  for (auto _ : state) {
    InterpolatedReference interp(ref, 16, 12);
    benchmark::DoNotOptimize(interp.whole_block(0, 0, 16, 16));
  }
}
BENCHMARK(BM_InterpolatedReference320);

// A 320x320 geometry image (a curved surface over a disc-shaped domain, 78 % of the pixels, and
// a texture) into its X, Y, Z and T planes: the encoder's first step for every frame.
void BM_QuantizeGeometry(benchmark::State& state) {
  const int size = 320;
  GeometryImage image;
  image.xyz_mm = cv::Mat(size, size, CV_32FC3);
  image.texture = cv::Mat(size, size, CV_32F);
  image.domain_mask = cv::Mat(size, size, CV_8U, cv::Scalar(0));
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> noise(-0.05f, 0.05f);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float u = x - size / 2.0f, v = y - size / 2.0f;
      image.xyz_mm.at<cv::Vec3f>(y, x) =
          cv::Vec3f(0.4f * u, 0.4f * v, 650.0f - 0.002f * (u * u + v * v) + noise(rng));
      image.texture.at<float>(y, x) = 0.5f + 0.4f * std::sin(0.05f * u);
      if (u * u + v * v < 0.25f * size * size) image.domain_mask.at<uint8_t>(y, x) = 255;
    }
  SequenceInfo info;
  info.width = info.height = size;
  info.bit_depth = 16;
  info.has_texture = true;
  info.domain_mask = image.domain_mask;
  info.box_min_mm = {-70, -70, 600};
  info.box_max_mm = {70, 70, 660};
  for (auto _ : state) benchmark::DoNotOptimize(quantize_geometry(image, info));
}
BENCHMARK(BM_QuantizeGeometry)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace gvkit::codec

BENCHMARK_MAIN();
