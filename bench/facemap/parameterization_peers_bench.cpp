// The harmonic solves of the map stage against CGAL's Surface_mesh_parameterization on the same
// 250K-vertex disk: the neutral ICT face rendered at 672 x 672 px (the clean bench's
// CleanScan/672 scan, 255K vertices), cleaned (about 247K vertices), its eyes and mouth filled.
// Both map the disk harmonically (plain cotangent weights: CGAL's discrete conformal map; or
// uniform weights: CGAL's barycentric / Tutte map) with the rim fixed on the unit circle by arc
// length, i.e. two sparse solves of one Laplacian. CGAL runs with its default solver (BiCGSTAB
// with an incomplete LUT preconditioner) and with Eigen's SparseLU (CGAL's system keeps the
// border's rows as identity rows, so it is not symmetric and a Cholesky factorization does not
// apply); gvkit with its direct solver (SimplicialLDLT of the free vertices' symmetric system,
// one AMD order for both) and its multigrid solver. Counter: flipped triangles of the result.
// Read the ratio within one run, not the absolute times.
#include <benchmark/benchmark.h>

#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Surface_mesh_parameterization/Barycentric_mapping_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/Circular_border_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/Discrete_conformal_map_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>

#include <Eigen/SparseLU>

#include <cmath>
#include <optional>

#include "bench_meshes.hpp"
#include "gvkit/facemap/face_cleaning.hpp"
#include "gvkit/facemap/harmonic_field.hpp"
#include "gvkit/facemap/synthetic_face_scan.hpp"

namespace gvkit::facemap::bench {
namespace {

namespace smp = CGAL::Surface_mesh_parameterization;
using Halfedge = boost::graph_traits<SurfaceMesh>::halfedge_descriptor;
using Point2 = Kernel::Point_2;

struct Fixture {
  Mesh disk;
  SurfaceMesh sm;
  TriSurface surface;
  std::vector<int> rim;  // surface vertices in boundary order
};

const Fixture* fixture() {
  static const Fixture* f = []() -> Fixture* {
    auto model = IctFaceModel::load(data_dir() / "ict-facekit", {"jawOpen"});
    if (!model.is_ok()) return nullptr;
    SyntheticFaceScanOptions o;
    o.size_px = 672;
    o.pixel_mm = 0.8 * 256.0 / o.size_px;
    const auto synthetic = render_synthetic_face_scan(*model, model->neutral_mm(), o);
    FaceLandmarks landmarks;
    landmarks.points_px = synthetic.landmarks.points_px;
    auto cleaned = clean_scan(synthetic.scan, landmarks);
    if (!cleaned.is_ok()) return nullptr;
    auto* f = new Fixture;
    f->disk = std::move(cleaned->mesh);
    if (!fill_holes(&f->disk).is_ok()) return nullptr;
    f->sm = to_cgal(f->disk);
    for (auto v : f->disk.vertices()) {
      const auto& p = f->disk.point(v);
      f->surface.xyz.emplace_back(p[0], p[1], p[2]);
    }
    for (auto face : f->disk.faces()) {
      std::array<int, 3> t{};
      int k = 0;
      for (auto v : f->disk.fv_range(face)) t[k++] = v.idx();
      f->surface.triangles.push_back(t);
    }
    const auto loops = tri_surface_boundary_loops(f->surface);
    if (loops.size() != 1) return nullptr;
    f->rim = loops[0];
    return f;
  }();
  return f;
}

// Triangles whose image has the minority orientation or zero area.
int flipped(const std::vector<std::array<int, 3>>& triangles, const std::vector<double>& u,
            const std::vector<double>& v) {
  int positive = 0, negative = 0;
  for (const auto& t : triangles) {
    const double a =
        (u[t[1]] - u[t[0]]) * (v[t[2]] - v[t[0]]) - (u[t[2]] - u[t[0]]) * (v[t[1]] - v[t[0]]);
    positive += a > 0, negative += a < 0;
  }
  return static_cast<int>(triangles.size()) - std::max(positive, negative);
}

// range(0): 0 = cotangent weights (discrete conformal map), 1 = uniform weights (Tutte);
// range(1): 0 = CGAL's default solver, 1 = SparseLU.
void BM_Cgal(benchmark::State& state) {
  const Fixture* f = fixture();
  if (!f) return state.SkipWithError("../shared/data absent or the face did not clean");
  using Lu = CGAL::Eigen_solver_traits<
      Eigen::SparseLU<CGAL::Eigen_sparse_matrix<double>::EigenType, Eigen::COLAMDOrdering<int>>>;
  using Border = smp::Circular_border_arc_length_parameterizer_3<SurfaceMesh>;
  std::vector<double> u, v;
  for (auto _ : state) {
    SurfaceMesh sm = f->sm;
    const Halfedge border = CGAL::Polygon_mesh_processing::longest_border(sm).first;
    auto uv = sm.add_property_map<SurfaceMesh::Vertex_index, Point2>("v:uv").first;
    smp::Error_code err = smp::OK;
    const bool tutte = state.range(0) != 0, lu = state.range(1) != 0;
    if (!tutte && !lu)
      err = smp::parameterize(sm, smp::Discrete_conformal_map_parameterizer_3<SurfaceMesh>(),
                              border, uv);
    else if (!tutte)
      err = smp::parameterize(
          sm, smp::Discrete_conformal_map_parameterizer_3<SurfaceMesh, Border, Lu>(), border, uv);
    else if (!lu)
      err = smp::parameterize(sm, smp::Barycentric_mapping_parameterizer_3<SurfaceMesh>(), border,
                              uv);
    else
      err = smp::parameterize(
          sm, smp::Barycentric_mapping_parameterizer_3<SurfaceMesh, Border, Lu>(), border, uv);
    if (err != smp::OK) return state.SkipWithError(smp::get_error_message(err));
    state.PauseTiming();
    u.clear(), v.clear();
    for (auto w : sm.vertices()) u.push_back(uv[w].x()), v.push_back(uv[w].y());
    state.ResumeTiming();
  }
  state.SetLabel(std::string(state.range(0) ? "Tutte" : "cotan") + ", " +
                 (state.range(1) ? "SparseLU" : "BiCGSTAB + ILUT (CGAL's default)"));
  state.counters["vertices"] = static_cast<double>(f->surface.n_vertices());
  state.counters["flipped"] = flipped(f->surface.triangles, u, v);
}
BENCHMARK(BM_Cgal)
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->ArgNames({"tutte", "lu"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// The same map with gvkit's Laplacian and solvers. range(0) as above; range(1): 0 = direct, 1 =
// multigrid. Timed: the Laplacian, the boundary and both solves (what CGAL's call does).
void BM_Gvkit(benchmark::State& state) {
  const Fixture* f = fixture();
  if (!f) return state.SkipWithError("../shared/data absent or the face did not clean");
  const TriSurface& s = f->surface;
  const int n = s.n_vertices();
  const bool tutte = state.range(0) != 0;
  const HarmonicSolver solver =
      state.range(1) ? HarmonicSolver::kMultigrid : HarmonicSolver::kDirect;
  std::vector<double> u, v;
  for (auto _ : state) {
    Eigen::SparseMatrix<double> laplacian;
    if (tutte) {
      std::vector<Eigen::Triplet<double>> entries;
      for (const auto& t : s.triangles)
        for (int k = 0; k < 3; ++k) {
          const int i = t[k], j = t[(k + 1) % 3];
          // Each interior edge is in two triangles: weight 1 in all.
          entries.emplace_back(i, j, -0.5), entries.emplace_back(j, i, -0.5);
          entries.emplace_back(i, i, 0.5), entries.emplace_back(j, j, 0.5);
        }
      for (size_t r = 0; r < f->rim.size(); ++r) {  // boundary edges are in one triangle
        const int i = f->rim[r], j = f->rim[(r + 1) % f->rim.size()];
        entries.emplace_back(i, j, -0.5), entries.emplace_back(j, i, -0.5);
        entries.emplace_back(i, i, 0.5), entries.emplace_back(j, j, 0.5);
      }
      laplacian.resize(n, n);
      laplacian.setFromTriplets(entries.begin(), entries.end());
    } else {
      laplacian = cotan_laplacian(s);
    }
    std::vector<char> fixed(n, 0);
    std::vector<double> bu(n, 0.0), bv(n, 0.0);
    const int m = static_cast<int>(f->rim.size());
    std::vector<double> arc(m + 1, 0.0);
    for (int i = 0; i < m; ++i)
      arc[i + 1] = arc[i] + (s.xyz[f->rim[(i + 1) % m]] - s.xyz[f->rim[i]]).norm();
    for (int i = 0; i < m; ++i) {
      const double angle = 2 * M_PI * arc[i] / arc[m];
      const int w = f->rim[i];
      fixed[w] = 1, bu[w] = 0.5 + 0.5 * std::cos(angle), bv[w] = 0.5 + 0.5 * std::sin(angle);
    }
    const std::vector<int> order = solver == HarmonicSolver::kDirect
                                       ? laplacian_elimination_order(laplacian)
                                       : std::vector<int>{};
    auto ru = solve_dirichlet(laplacian, fixed, bu, order, solver);
    auto rv = solve_dirichlet(laplacian, fixed, bv, order, solver);
    if (!ru.is_ok() || !rv.is_ok()) return state.SkipWithError("solve failed");
    u = std::move(ru).value(), v = std::move(rv).value();
  }
  state.SetLabel(std::string(tutte ? "Tutte" : "cotan") + ", " +
                 (state.range(1) ? "multigrid" : "direct (SimplicialLDLT, one AMD order)"));
  state.counters["vertices"] = static_cast<double>(n);
  state.counters["flipped"] = flipped(s.triangles, u, v);
}
BENCHMARK(BM_Gvkit)
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->ArgNames({"tutte", "multigrid"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
}  // namespace gvkit::facemap::bench

BENCHMARK_MAIN();
