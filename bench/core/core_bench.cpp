// core benchmarks.
// - Float formatting of the ASCII mesh writers: write_shortest_float against std::to_chars (the
//   same text) on the values of a mesh file: per vertex 3 coordinates in mm, 3 normal components
//   and 5 values in [0, 1] (texture coordinates, grey levels), random in those ranges.
// - A geometry image's EXR written and read with each ExrCompression: the file named by
//   GVKIT_BENCH_EXR (a frame_NNNNNN.exr of a geometry video), else a synthetic 320x320 frame (a
//   curved surface with 0.05 mm of noise, a textured disc of a domain).
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/shortest_float.hpp"

namespace gvkit {
namespace {

const std::vector<float>& mesh_values() {
  static const std::vector<float> values = [] {
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> position(-150, 150), normal(-1, 1), unit(0, 1);
    std::vector<float> v(1100000);
    for (size_t i = 0; i < v.size(); ++i)
      v[i] = i % 11 < 3 ? position(rng) : (i % 11 < 6 ? normal(rng) : unit(rng));
    return v;
  }();
  return values;
}

// fast:0 std::to_chars, fast:1 write_shortest_float; time per value.
void BM_FormatFloats(benchmark::State& state) {
  const std::vector<float>& values = mesh_values();
  std::vector<char> text(values.size() * 16 + kShortestFloatRoom);
  for (auto _ : state) {
    char* p = text.data();
    if (state.range(0))
      for (const float v : values) p = write_shortest_float(p, v);
    else
      for (const float v : values) p = std::to_chars(p, p + kShortestFloatRoom, v).ptr;
    benchmark::DoNotOptimize(p);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(values.size()));
}
BENCHMARK(BM_FormatFloats)->Arg(0)->Arg(1)->ArgName("fast")->Unit(benchmark::kMillisecond);

const GeometryImage& bench_geometry_image() {
  static const GeometryImage image = [] {
    if (const char* path = std::getenv("GVKIT_BENCH_EXR")) {
      Result<GeometryImage> read = read_geometry_image_exr(path);
      if (!read.is_ok()) throw std::runtime_error(read.status().message());
      return *read;
    }
    const int n = 320;
    GeometryImage g;
    g.xyz_mm.create(n, n, CV_32FC3);
    g.texture.create(n, n, CV_32F);
    g.domain_mask = cv::Mat(n, n, CV_8U, cv::Scalar(0));
    std::mt19937 rng(2);
    std::normal_distribution<float> noise(0, 0.05f);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const float u = (x - n / 2) * 0.6f, v = (y - n / 2) * 0.6f;
        g.xyz_mm.at<cv::Vec3f>(y, x) =
            cv::Vec3f(u + noise(rng), v + noise(rng), 650 - 0.004f * (u * u + v * v) + noise(rng));
        g.texture.at<float>(y, x) =
            0.5f + 0.3f * std::sin(0.05f * x) * std::cos(0.07f * y) + 0.02f * noise(rng);
        if ((x - n / 2) * (x - n / 2) + (y - n / 2) * (y - n / 2) < n * n / 4)
          g.domain_mask.at<uint8_t>(y, x) = 255;
      }
    return g;
  }();
  return image;
}

// compression: 0 ZIP, 1 RLE, 2 none; write:1 times write_geometry_image_exr, write:0
// read_geometry_image_exr of the file it wrote. Counter bytes: the file's size.
void BM_GeometryImageExr(benchmark::State& state) {
  const ExrCompression compression = static_cast<ExrCompression>(state.range(0));
  const GeometryImage& image = bench_geometry_image();
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("gvkit_core_bench_" + std::string(exr_compression_name(compression)) + ".exr");
  if (!write_geometry_image_exr(path, image, compression).is_ok())
    throw std::runtime_error(path.string() + ": cannot write");
  for (auto _ : state) {
    if (state.range(1)) {
      benchmark::DoNotOptimize(write_geometry_image_exr(path, image, compression).is_ok());
    } else {
      Result<GeometryImage> back = read_geometry_image_exr(path);
      benchmark::DoNotOptimize(back.is_ok());
    }
  }
  state.counters["bytes"] = static_cast<double>(std::filesystem::file_size(path));
  std::filesystem::remove(path);
}
BENCHMARK(BM_GeometryImageExr)
    ->ArgsProduct({{0, 1, 2}, {1, 0}})
    ->ArgNames({"compression", "write"})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gvkit
