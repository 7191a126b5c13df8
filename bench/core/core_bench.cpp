// Float formatting of the ASCII mesh writers: write_shortest_float against std::to_chars (the
// same text) on the values of a mesh file: per vertex 3 coordinates in mm, 3 normal components
// and 5 values in [0, 1] (texture coordinates, grey levels), random in those ranges.
#include <charconv>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

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

}  // namespace
}  // namespace gvkit
