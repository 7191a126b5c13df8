// facemap map stage: time of each step of the expression-invariant map (cuts, harmonic field and
// conjugate, resampling) and of the harmonic-map baseline, on ICT-FaceKit faces (9,409 vertices)
// and on the face frames of a `gvkit facemap clean` output (GVKIT_BENCH_FACES=FOLDER, its first
// frame).
#include <benchmark/benchmark.h>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/face_landmarks_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "gvkit/facemap/block_matching.hpp"
#include "gvkit/facemap/canonical_domain.hpp"
#include "gvkit/facemap/eip_map.hpp"
#include "gvkit/facemap/face_annulus.hpp"
#include "gvkit/facemap/face_cleaning.hpp"
#include "gvkit/facemap/flow_coordinates.hpp"
#include "gvkit/facemap/harmonic_field.hpp"
#include "gvkit/facemap/harmonic_map_baseline.hpp"
#include "gvkit/facemap/multigrid_solver.hpp"
#include "gvkit/facemap/synthetic_face_scan.hpp"

namespace gvkit::facemap {
namespace {

struct Face {
  Mesh mesh;
  FaceLandmarks landmarks;
};

// range(0): 0 = ICT neutral, 1 = ICT jaw half open + smile, 2 = first frame of
// $GVKIT_BENCH_FACES, 3 = the 250K-vertex face: the neutral ICT face rendered at 672 x 672 px
// (the clean bench's CleanScan/672 scan, 255K vertices) and cleaned (about 247K vertices).
const Face* face(int which) {
  static std::map<int, std::optional<Face>> cache;
  auto it = cache.find(which);
  if (it != cache.end()) return it->second ? &*it->second : nullptr;
  std::optional<Face> out;
  if (which < 2) {
    auto model = IctFaceModel::load(std::filesystem::path(GVKIT_SHARED_DATA_DIR) / "ict-facekit",
                                    {"jawOpen", "mouthSmile_L"});
    if (model.is_ok()) {
      const auto pos = which == 0 ? model->neutral_mm()
                                  : model->evaluate({{"jawOpen", 0.5}, {"mouthSmile_L", 0.5}});
      Face f{model->face_mesh(pos), {}};
      for (int v : model->landmark_vertices())
        f.landmarks.points_mm.emplace_back(pos[v][0], pos[v][1], pos[v][2]);
      out = std::move(f);
    }
  } else if (which == 3) {
    auto model = IctFaceModel::load(std::filesystem::path(GVKIT_SHARED_DATA_DIR) / "ict-facekit",
                                    {"jawOpen"});
    if (model.is_ok()) {
      SyntheticFaceScanOptions o;
      o.size_px = 672;
      o.pixel_mm = 0.8 * 256.0 / o.size_px;
      const auto synthetic = render_synthetic_face_scan(*model, model->neutral_mm(), o);
      FaceLandmarks landmarks;
      landmarks.points_px = synthetic.landmarks.points_px;
      auto cleaned = clean_scan(synthetic.scan, landmarks);
      if (cleaned.is_ok()) out = Face{std::move(cleaned->mesh), std::move(cleaned->landmarks)};
    }
  } else if (const char* dir = std::getenv("GVKIT_BENCH_FACES")) {
    auto files = list_frame_files(dir, ".ply");
    if (files.is_ok() && !files->empty()) {
      auto mesh = read_mesh(files->front().path);
      auto lm = read_face_landmarks(frame_path(dir, files->front().index, ".landmarks.json"));
      if (mesh.is_ok() && lm.is_ok()) out = Face{std::move(mesh).value(), std::move(lm).value()};
    }
  }
  cache[which] = std::move(out);
  return cache[which] ? &*cache[which] : nullptr;
}

const CanonicalDomain* domain(int size) {
  static std::map<int, std::optional<CanonicalDomain>> cache;
  auto it = cache.find(size);
  if (it == cache.end()) {
    std::optional<CanonicalDomain> d;
    auto spec = CanonicalDomainSpec::load_default();
    if (spec.is_ok()) {
      auto made = CanonicalDomain::create(*spec, {size, size});
      if (made.is_ok()) d = std::move(made).value();
    }
    it = cache.emplace(size, std::move(d)).first;
  }
  return it->second ? &*it->second : nullptr;
}

#define REQUIRE_FACE(state)                               \
  const Face* f = face(static_cast<int>(state.range(0))); \
  if (!f) return state.SkipWithError("face absent (../shared/data or GVKIT_BENCH_FACES)")

// Once per size: the canonical domain (grid mesh, cuts, harmonic field, conjugate).
void BM_CanonicalDomain(benchmark::State& state) {
  auto spec = CanonicalDomainSpec::load_default();
  if (!spec.is_ok()) return state.SkipWithError("no canonical domain spec");
  const int n = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(CanonicalDomain::create(*spec, {n, n}));
}
BENCHMARK(BM_CanonicalDomain)->Arg(128)->Arg(320)->Unit(benchmark::kMillisecond);

// Cuts c and d and the annulus; range(1): 0 = edge paths only, 1 = descent paths with the
// distance fields solved on the whole mesh (the reference), 2 = descent paths with the fields
// solved on the crop around the cut routes (the default).
void BM_FaceAnnulus(benchmark::State& state) {
  REQUIRE_FACE(state);
  FaceAnnulusOptions o;
  o.descent_paths = state.range(1) != 0;
  if (state.range(1) == 1) o.distance_crop_mm = 0;
  const auto distance = heat_geodesic_distance();
  for (auto _ : state) {
    auto a = make_face_annulus(f->mesh, f->landmarks, distance, o);
    if (!a.is_ok()) return state.SkipWithError(a.status().message().c_str());
    benchmark::DoNotOptimize(a);
  }
}
BENCHMARK(BM_FaceAnnulus)
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1, 2}})
    ->ArgNames({"face", "cuts"})
    ->Unit(benchmark::kMillisecond);

// f, its conjugate, the boundary correspondence and the untangling of flips.
void BM_FlowCoordinates(benchmark::State& state) {
  REQUIRE_FACE(state);
  const CanonicalDomain* d = domain(64);
  if (!d) return state.SkipWithError("no canonical domain");
  auto a = make_face_annulus(f->mesh, f->landmarks, heat_geodesic_distance());
  if (!a.is_ok()) return state.SkipWithError(a.status().message().c_str());
  if (a->key_names() != d->key_names()) a->reverse_orientation();
  for (auto _ : state) benchmark::DoNotOptimize(flow_coordinates(*a, d->key_u()));
}
BENCHMARK(BM_FlowCoordinates)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);

// f and psi of the annulus: range(1) = 0 orders each reduced system on its own (the reference),
// 1 uses one elimination order of the whole Laplacian for both (what flow_coordinates does).
void BM_HarmonicSolves(benchmark::State& state) {
  REQUIRE_FACE(state);
  auto a = make_face_annulus(f->mesh, f->landmarks, heat_geodesic_distance());
  if (!a.is_ok()) return state.SkipWithError(a.status().message().c_str());
  const TriSurface& s = a->surface;
  std::vector<char> fixed(s.n_vertices(), 0);
  std::vector<double> value(s.n_vertices(), 0.0);
  for (int v : a->outer_loop) fixed[v] = 1;
  for (int v : a->inner_loop) fixed[v] = 1, value[v] = 1.0;
  const auto laplacian = cotan_laplacian(s);
  for (auto _ : state) {
    const std::vector<int> order =
        state.range(1) ? laplacian_elimination_order(laplacian) : std::vector<int>{};
    benchmark::DoNotOptimize(solve_dirichlet(laplacian, fixed, value, order));
    benchmark::DoNotOptimize(harmonic_conjugate(s, laplacian, a->inner_loop, a->outer_loop, order));
  }
}
BENCHMARK(BM_HarmonicSolves)
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1}})
    ->ArgNames({"face", "one_order"})
    ->Unit(benchmark::kMillisecond);

// f's Dirichlet system on a face's annulus (the free vertices' rows and columns of the floored
// cotangent Laplacian; b = ones), or with neumann the whole Laplacian, which is singular (psi's
// system; b = a vector summing to zero). Built once per face.
struct DirichletSystem {
  Eigen::SparseMatrix<double> a;
  Eigen::VectorXd b;
};
const DirichletSystem* dirichlet_system(int which, bool neumann) {
  static std::map<std::pair<int, bool>, std::optional<DirichletSystem>> cache;
  const auto key = std::make_pair(which, neumann);
  if (auto it = cache.find(key); it != cache.end()) return it->second ? &*it->second : nullptr;
  std::optional<DirichletSystem>& out = cache[key];
  const Face* f = face(which);
  if (!f) return nullptr;
  auto annulus = make_face_annulus(f->mesh, f->landmarks, heat_geodesic_distance());
  if (!annulus.is_ok()) return nullptr;
  const TriSurface& s = annulus->surface;
  const int n = s.n_vertices();
  const auto laplacian = cotan_laplacian(s, kDefaultMinCotanWeight);
  DirichletSystem sys;
  if (neumann) {
    sys.a = laplacian;
    sys.b = Eigen::VectorXd::LinSpaced(n, -1.0, 1.0);
    sys.b.array() -= sys.b.mean();
  } else {
    std::vector<char> fixed(n, 0);
    for (int v : annulus->outer_loop) fixed[v] = 1;
    for (int v : annulus->inner_loop) fixed[v] = 1;
    std::vector<int> index(n, -1);
    int m = 0;
    for (int v = 0; v < n; ++v)
      if (!fixed[v]) index[v] = m++;
    std::vector<Eigen::Triplet<double>> entries;
    for (int col = 0; col < n; ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(laplacian, col); it; ++it)
        if (index[col] >= 0 && index[it.row()] >= 0)
          entries.emplace_back(index[it.row()], index[col], it.value());
    sys.a.resize(m, m);
    sys.a.setFromTriplets(entries.begin(), entries.end());
    sys.b = Eigen::VectorXd::Ones(m);
  }
  out = std::move(sys);
  return &*out;
}

// f's system (the annulus's Laplacian, floored weights, restricted to the free vertices) on each
// sparse solver. range(1): 0 = Eigen SimplicialLDLT with its AMD order (what the direct path
// factorizes), 1 = CHOLMOD supernodal LL' (reference BLAS), 2 = CHOLMOD simplicial LDL',
// 3 = MultigridSolver (counters: setup and solve wall ms, iterations, levels, max_err = the
// largest difference to the LDLT solution over its largest value).
void BM_DirichletSolvers(benchmark::State& state) {
  const DirichletSystem* sys = dirichlet_system(static_cast<int>(state.range(0)), false);
  if (!sys) return state.SkipWithError("face absent or no annulus");
  const Eigen::SparseMatrix<double>& system = sys->a;
  const Eigen::VectorXd& b = sys->b;
  const auto m = system.rows();
  double nnz = 0;
  Eigen::VectorXd reference;
  if (state.range(1) == 3)
    reference = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(system).solve(b);
  for (auto _ : state) {
    if (state.range(1) == 0) {
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(system);
      benchmark::DoNotOptimize(solver.solve(b));
      nnz = solver.matrixL().nestedExpression().nonZeros();
    } else if (state.range(1) == 1) {
      Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> solver(system);
      benchmark::DoNotOptimize(solver.solve(b));
      nnz = solver.cholmod().lnz;
    } else if (state.range(1) == 2) {
      Eigen::CholmodSimplicialLDLT<Eigen::SparseMatrix<double>> solver(system);
      benchmark::DoNotOptimize(solver.solve(b));
      nnz = solver.cholmod().lnz;
    } else {
      MultigridSolver solver;
      auto t0 = std::chrono::steady_clock::now();
      if (!solver.compute(system).is_ok()) return state.SkipWithError("multigrid setup failed");
      auto t1 = std::chrono::steady_clock::now();
      Eigen::VectorXd x;
      const Status status = solver.solve(b, &x);
      auto t2 = std::chrono::steady_clock::now();
      state.counters["setup_ms"] = std::chrono::duration<double, std::milli>(t1 - t0).count();
      state.counters["solve_ms"] = std::chrono::duration<double, std::milli>(t2 - t1).count();
      if (!status.is_ok()) return state.SkipWithError(status.message().c_str());
      state.counters["iterations"] = solver.iterations();
      state.counters["levels"] = solver.levels();
      state.counters["max_err"] = (reference - x).cwiseAbs().maxCoeff() / x.cwiseAbs().maxCoeff();
    }
  }
  state.counters["unknowns"] = m;
  state.counters["nnz_L"] = nnz;
}
BENCHMARK(BM_DirichletSolvers)->ArgsProduct({{2, 3}, {0, 1, 2, 3}})->Unit(benchmark::kMillisecond);

// The multigrid's hierarchy alone (compute) and its solve alone, on f's Dirichlet system
// (neumann:0) and on the whole singular Laplacian as psi's (neumann:1), CPU time per call.
void BM_MultigridCompute(benchmark::State& state) {
  const bool neumann = state.range(1) != 0;
  const DirichletSystem* sys = dirichlet_system(static_cast<int>(state.range(0)), neumann);
  if (!sys) return state.SkipWithError("face absent or no annulus");
  MultigridOptions options;
  options.constant_null_space = neumann;
  for (auto _ : state) {
    MultigridSolver solver(options);
    if (!solver.compute(sys->a).is_ok()) return state.SkipWithError("multigrid setup failed");
    state.counters["levels"] = solver.levels();
  }
  state.counters["unknowns"] = static_cast<double>(sys->a.rows());
}
BENCHMARK(BM_MultigridCompute)
    ->ArgsProduct({{2, 3}, {0, 1}})
    ->ArgNames({"face", "neumann"})
    ->Unit(benchmark::kMillisecond);

void BM_MultigridSolve(benchmark::State& state) {
  const bool neumann = state.range(1) != 0;
  const DirichletSystem* sys = dirichlet_system(static_cast<int>(state.range(0)), neumann);
  if (!sys) return state.SkipWithError("face absent or no annulus");
  MultigridOptions options;
  options.constant_null_space = neumann;
  MultigridSolver solver(options);
  if (!solver.compute(sys->a).is_ok()) return state.SkipWithError("multigrid setup failed");
  Eigen::VectorXd x;
  for (auto _ : state) {
    x.resize(0);
    if (!solver.solve(sys->b, &x).is_ok()) return state.SkipWithError("multigrid solve failed");
  }
  state.counters["iterations"] = solver.iterations();
  state.counters["residual"] = solver.residual();
  const Eigen::VectorXd r = sys->b - sys->a * x;
  state.counters["check_residual"] = r.norm() / sys->b.norm();
}
BENCHMARK(BM_MultigridSolve)
    ->ArgsProduct({{2, 3}, {0, 1}})
    ->ArgNames({"face", "neumann"})
    ->Unit(benchmark::kMillisecond);

// The whole map of one frame onto a prepared domain (cuts, fields, resampling, metrics).
void BM_MapFaceEip(benchmark::State& state) {
  REQUIRE_FACE(state);
  const CanonicalDomain* d = domain(static_cast<int>(state.range(1)));
  if (!d) return state.SkipWithError("no canonical domain");
  const auto distance = heat_geodesic_distance();
  for (auto _ : state) {
    auto m = map_face_eip(f->mesh, f->landmarks, *d, distance);
    if (!m.is_ok()) return state.SkipWithError(m.status().message().c_str());
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_MapFaceEip)
    ->ArgsProduct({{0, 1, 2, 3}, {320}})
    ->ArgNames({"face", "size"})
    ->Unit(benchmark::kMillisecond);

void BM_MapFaceHm(benchmark::State& state) {
  REQUIRE_FACE(state);
  for (auto _ : state) {
    auto m = map_face_hm(f->mesh, f->landmarks, {320, 320});
    if (!m.is_ok()) return state.SkipWithError(m.status().message().c_str());
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_MapFaceHm)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);

// The temporal MSE of `facemap map` (full-search block matching) between frames 0 and 1 of the
// geometry images in $GVKIT_BENCH_GV (a `facemap map` output), else between the 320 x 320 maps of
// ICT faces 0 and 1. range(0): 0 = block_matching_error_reference, 1 = block_matching_error
// (AVX2 where the processor has it).
void BM_BlockMatching(benchmark::State& state) {
  static const std::optional<std::pair<GeometryImage, GeometryImage>> frames =
      []() -> std::optional<std::pair<GeometryImage, GeometryImage>> {
    if (const char* dir = std::getenv("GVKIT_BENCH_GV")) {
      auto a = read_geometry_image_exr(std::filesystem::path(dir) / "frame_000000.exr");
      auto b = read_geometry_image_exr(std::filesystem::path(dir) / "frame_000001.exr");
      if (!a.is_ok() || !b.is_ok()) return std::nullopt;
      return std::pair(*a, *b);
    }
    const CanonicalDomain* d = domain(320);
    const Face* f0 = face(0);
    const Face* f1 = face(1);
    if (!d || !f0 || !f1) return std::nullopt;
    auto a = map_face_eip(f0->mesh, f0->landmarks, *d, heat_geodesic_distance());
    auto b = map_face_eip(f1->mesh, f1->landmarks, *d, heat_geodesic_distance());
    if (!a.is_ok() || !b.is_ok()) return std::nullopt;
    return std::pair(a->image, b->image);
  }();
  if (!frames) return state.SkipWithError("no geometry images ($GVKIT_BENCH_GV or ../shared/data)");
  double mse = 0;
  for (auto _ : state) {
    auto e = state.range(0) ? block_matching_error(frames->first, frames->second)
                            : block_matching_error_reference(frames->first, frames->second);
    if (!e.is_ok()) return state.SkipWithError(e.status().message().c_str());
    mse = e->mean_mse_mm2;
  }
  state.counters["mean_mse_mm2"] = mse;
  state.SetLabel(state.range(0) ? "dispatch" : "reference");
}
BENCHMARK(BM_BlockMatching)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gvkit::facemap

BENCHMARK_MAIN();
