// Timings of the surface metrics (surface_metrics.hpp: normal error and Hausdorff distance of a
// decoded geometry image against its input, as `gvkit encode`, `decode --reference` and
// `compare` measure every frame) and of their point-to-triangle kernels against the plain
// references (Arg 0 = the optimised kernel, AVX2 where the processor has it; 1 = the reference).
//
// The frame pair is synthetic by default: a 320x320 face-sized bump (0.6 mm pixels, a disc mask)
// with 0.05 mm of noise, decoded = input + 0.03 mm of noise per coordinate. Real frames: set
// GVKIT_BENCH_SURFACE_REFERENCE=IN.exr and GVKIT_BENCH_SURFACE_DECODED=OUT.exr, then run
//   build/bench/codec/codec_surface_metrics_benchmark
#include <cmath>
#include <cstdlib>
#include <random>
#include <stdexcept>
#include <vector>

#include <benchmark/benchmark.h>

#include "gvkit/codec/point_triangle_distance.hpp"
#include "gvkit/codec/surface_metrics.hpp"
#include "gvkit/core/exr_io.hpp"

namespace gvkit::codec {
namespace {

constexpr int kSize = 320;

GeometryImage synthetic_input() {
  GeometryImage g;
  g.xyz_mm.create(kSize, kSize, CV_32FC3);
  g.domain_mask.create(kSize, kSize, CV_8U);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const double u = 0.6 * (x - kSize / 2), v = 0.6 * (y - kSize / 2);
      const double z = 60 * std::exp(-(u * u + v * v) / (2 * 45.0 * 45.0)) +
                       4 * std::sin(u / 9) * std::cos(v / 13);
      g.xyz_mm.at<cv::Vec3f>(y, x) =
          cv::Vec3f(static_cast<float>(u + noise(rng)), static_cast<float>(v + noise(rng)),
                    static_cast<float>(z + noise(rng)));
      g.domain_mask.at<uint8_t>(y, x) = u * u + v * v <= 90.0 * 90.0 ? 255 : 0;
    }
  return g;
}

GeometryImage perturbed(const GeometryImage& g, double sigma_mm) {
  GeometryImage d = g;
  d.xyz_mm = g.xyz_mm.clone();
  std::mt19937 rng(6);
  std::normal_distribution<double> noise(0.0, sigma_mm);
  for (int y = 0; y < d.xyz_mm.rows; ++y)
    for (int x = 0; x < d.xyz_mm.cols; ++x)
      for (int k = 0; k < 3; ++k) d.xyz_mm.at<cv::Vec3f>(y, x)[k] += static_cast<float>(noise(rng));
  return d;
}

GeometryImage read_or_throw(const char* path) {
  Result<GeometryImage> r = read_geometry_image_exr(path);
  if (!r.is_ok()) throw std::runtime_error(r.status().message());
  return std::move(r).value();
}

// The pair the benchmarks measure: the environment's EXRs, or the synthetic pair.
struct FramePair {
  GeometryImage input, decoded;
  FramePair() {
    const char* in = std::getenv("GVKIT_BENCH_SURFACE_REFERENCE");
    const char* out = std::getenv("GVKIT_BENCH_SURFACE_DECODED");
    if (in && out) {
      input = read_or_throw(in);
      decoded = read_or_throw(out);
    } else {
      input = synthetic_input();
      decoded = perturbed(input, 0.03);
    }
  }
};

const FramePair& frames() {
  static const FramePair pair;
  return pair;
}

void BM_SurfaceError(benchmark::State& state) {
  const FramePair& f = frames();
  for (auto _ : state) benchmark::DoNotOptimize(surface_error(f.input, f.decoded));
  state.SetItemsProcessed(state.iterations());  // frames
}
BENCHMARK(BM_SurfaceError)->Unit(benchmark::kMillisecond);

void BM_NormalError(benchmark::State& state) {
  const FramePair& f = frames();
  for (auto _ : state) benchmark::DoNotOptimize(normal_error_deg(f.input, f.decoded));
}
BENCHMARK(BM_NormalError)->Unit(benchmark::kMillisecond);

void BM_SurfaceDistance(benchmark::State& state) {
  const FramePair& f = frames();
  for (auto _ : state) benchmark::DoNotOptimize(surface_distance_mm(f.input, f.decoded));
}
BENCHMARK(BM_SurfaceDistance)->Unit(benchmark::kMillisecond);

// The eight triangles of the 2x2 quads around each interior pixel of the synthetic input, and a
// point 0.03 mm off the pixel's vertex: what the search evaluates first for every pixel.
void BM_NearestTriangle(benchmark::State& state) {
  const GeometryImage g = synthetic_input();
  std::vector<double> x, y, z;
  for (int i = 0; i < kSize * kSize; ++i) {
    const cv::Vec3f& v = g.xyz_mm.at<cv::Vec3f>(i / kSize, i % kSize);
    x.push_back(v[0]);
    y.push_back(v[1]);
    z.push_back(v[2]);
  }
  const VertexArrays vertices{x.data(), y.data(), z.data()};
  std::vector<int32_t> a, b, c;
  for (int dy = -1; dy <= 0; ++dy)
    for (int dx = -1; dx <= 0; ++dx) {
      const int i00 = dy * kSize + dx, i10 = i00 + 1, i01 = i00 + kSize, i11 = i01 + 1;
      a.insert(a.end(), {i00, i00});
      b.insert(b.end(), {i10, i11});
      c.insert(c.end(), {i11, i01});
    }
  std::vector<int32_t> pa(8), pb(8), pc(8);
  const bool plain = state.range(0) != 0;
  double sum = 0;
  int pixel = kSize + 1;
  for (auto _ : state) {
    for (int k = 0; k < 8; ++k) {
      pa[k] = a[k] + pixel;
      pb[k] = b[k] + pixel;
      pc[k] = c[k] + pixel;
    }
    const cv::Vec3d p(x[pixel] + 0.03, y[pixel] - 0.02, z[pixel] + 0.03);
    const TriangleIndices t{pa.data(), pb.data(), pc.data()};
    sum += plain ? nearest_triangle_distance2_reference(p, vertices, t, 8, HUGE_VAL)
                 : nearest_triangle_distance2(p, vertices, t, 8, HUGE_VAL);
    pixel = pixel + 1 < kSize * (kSize - 1) ? pixel + 1 : kSize + 1;
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(8 * state.iterations());  // triangles
}
BENCHMARK(BM_NearestTriangle)->Arg(0)->Arg(1);

}  // namespace
}  // namespace gvkit::codec

BENCHMARK_MAIN();
