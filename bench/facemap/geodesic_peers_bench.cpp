// Geodesic distance on the ICT face (about 9.5K vertices) from the nose tip: our heat method
// and fast marching against CGAL's Heat_method_3 (intrinsic Delaunay) and, as the truth, CGAL's
// exact Surface_mesh_shortest_path (Chen and Han). Counters: mean and max relative error against
// the exact distances (vertices farther than 5 mm).
#include <benchmark/benchmark.h>

#include <CGAL/Heat_method_3/Surface_mesh_geodesic_distances_3.h>
#include <CGAL/Surface_mesh_shortest_path.h>

#include "bench_meshes.hpp"
#include "gvkit/facemap/fast_marching.hpp"
#include "gvkit/facemap/geodesic_distance.hpp"

namespace gvkit::facemap::bench {
namespace {

struct Fixture {
  Mesh mesh;
  SurfaceMesh sm;
  int source = 0;
  std::vector<double> exact;
};

const Fixture* fixture() {
  static const Fixture* f = []() -> Fixture* {
    auto face = ict_face();
    if (!face) return nullptr;
    auto* f = new Fixture;
    f->mesh = std::move(*face);
    f->sm = to_cgal(f->mesh);
    // Source: the vertex with the largest z (the nose tip of the frontal ICT face).
    for (auto v : f->mesh.vertices())
      if (f->mesh.point(v)[2] > f->mesh.point(f->mesh.vertex_handle(f->source))[2])
        f->source = v.idx();
    using Traits = CGAL::Surface_mesh_shortest_path_traits<Kernel, SurfaceMesh>;
    CGAL::Surface_mesh_shortest_path<Traits> paths(f->sm);
    paths.add_source_point(SurfaceMesh::Vertex_index(f->source));
    for (auto v : f->sm.vertices())
      f->exact.push_back(paths.shortest_distance_to_source_points(v).first);
    return f;
  }();
  return f;
}

void report(benchmark::State& state, const std::vector<double>& d) {
  const Fixture& f = *fixture();
  double sum = 0, worst = 0;
  int n = 0;
  for (size_t i = 0; i < d.size(); ++i) {
    if (f.exact[i] < 5.0) continue;
    const double rel = std::abs(d[i] - f.exact[i]) / f.exact[i];
    sum += rel;
    worst = std::max(worst, rel);
    ++n;
  }
  state.counters["mean_rel_err"] = sum / n;
  state.counters["max_rel_err"] = worst;
  state.counters["vertices"] = static_cast<double>(d.size());
}

void BM_ExactShortestPath(benchmark::State& state) {
  if (!fixture()) return state.SkipWithError("../shared/data absent");
  const Fixture& f = *fixture();
  using Traits = CGAL::Surface_mesh_shortest_path_traits<Kernel, SurfaceMesh>;
  for (auto _ : state) {
    CGAL::Surface_mesh_shortest_path<Traits> paths(f.sm);
    paths.add_source_point(SurfaceMesh::Vertex_index(f.source));
    paths.build_sequence_tree();
  }
  state.counters["vertices"] = static_cast<double>(f.mesh.n_vertices());
}
BENCHMARK(BM_ExactShortestPath)->Unit(benchmark::kMillisecond);

void BM_CgalHeatMethod(benchmark::State& state) {
  if (!fixture()) return state.SkipWithError("../shared/data absent");
  const Fixture& f = *fixture();
  std::vector<double> d(f.mesh.n_vertices());
  for (auto _ : state) {
    SurfaceMesh sm = f.sm;
    auto map = sm.add_property_map<SurfaceMesh::Vertex_index, double>("v:d", 0).first;
    CGAL::Heat_method_3::Surface_mesh_geodesic_distances_3<SurfaceMesh,
                                                           CGAL::Heat_method_3::Intrinsic_Delaunay>
        heat(sm);
    heat.add_source(SurfaceMesh::Vertex_index(f.source));
    heat.estimate_geodesic_distances(map);
    for (auto v : sm.vertices()) d[v.idx()] = map[v];
  }
  report(state, d);
}
BENCHMARK(BM_CgalHeatMethod)->Unit(benchmark::kMillisecond);

void BM_OurHeatMethod(benchmark::State& state) {
  if (!fixture()) return state.SkipWithError("../shared/data absent");
  const Fixture& f = *fixture();
  HeatGeodesicsOptions options;
  options.intrinsic_delaunay = state.range(0) != 0;
  options.average_boundary_conditions = state.range(1) != 0;
  std::vector<double> d;
  for (auto _ : state) {
    HeatGeodesics heat(f.mesh, options);
    d = heat.distance({f.mesh.vertex_handle(f.source)});
  }
  state.SetLabel(std::string(state.range(0) ? "intrinsic Delaunay" : "cotan") +
                 (state.range(1) ? ", averaged boundary conditions" : ", Neumann"));
  report(state, d);
}
BENCHMARK(BM_OurHeatMethod)
    ->Args({1, 0})
    ->Args({0, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond);

// One more query on a kept factorisation (the face mask makes four).
void BM_OurHeatMethodQuery(benchmark::State& state) {
  if (!fixture()) return state.SkipWithError("../shared/data absent");
  const Fixture& f = *fixture();
  HeatGeodesics heat(f.mesh);
  for (auto _ : state) benchmark::DoNotOptimize(heat.distance({f.mesh.vertex_handle(f.source)}));
}
BENCHMARK(BM_OurHeatMethodQuery)->Unit(benchmark::kMillisecond);

// Fast marching (the face mask's default): precomputation + one query.
void BM_OurFastMarching(benchmark::State& state) {
  if (!fixture()) return state.SkipWithError("../shared/data absent");
  const Fixture& f = *fixture();
  std::vector<double> d;
  for (auto _ : state) {
    FastMarching marching(f.mesh);
    d = marching.distance({f.mesh.vertex_handle(f.source)});
  }
  report(state, d);
}
BENCHMARK(BM_OurFastMarching)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gvkit::facemap::bench

BENCHMARK_MAIN();
