// facemap clean stage: time per frame on synthetic ICT scans, the heat-geodesics solvers side by
// side, and mask consistency over an ICT expression sequence (the true surface points on the
// mask rim, mapped back to the neutral face, against the neutral frame's rim).
#include <benchmark/benchmark.h>

#include <opencv2/imgcodecs.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "gvkit/core/allocator_tuning.hpp"
#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/mesh_topology.hpp"
#include "gvkit/facemap/face_cleaning.hpp"
#include "gvkit/facemap/fast_marching.hpp"
#include "gvkit/facemap/geodesic_distance.hpp"
#include "gvkit/facemap/landmark_detector.hpp"
#include "gvkit/facemap/mesh_repair.hpp"
#include "gvkit/facemap/surface_distance.hpp"
#include "gvkit/facemap/synthetic_face_scan.hpp"

namespace gvkit::facemap {
namespace {

// The heap settings of the gvkit program (tools/main.cpp), so the times are those of its frames.
const bool kAllocatorTuned = tune_allocator_for_frames();

const IctFaceModel* ict() {
  static const IctFaceModel* model = [] {
    auto m = IctFaceModel::load(std::filesystem::path(GVKIT_SHARED_DATA_DIR) / "ict-facekit",
                                {"jawOpen", "mouthSmile_L", "mouthSmile_R", "browInnerUp_L",
                                 "browInnerUp_R", "eyeBlink_L", "eyeBlink_R"});
    return m.is_ok() ? new IctFaceModel(std::move(m).value()) : nullptr;
  }();
  return model;
}

// Whole clean stage on one synthetic scan of size x size px (true landmarks; detection apart).
// CPU time is the figure to read; the counters are wall times of the steps.
void BM_CleanScan(benchmark::State& state) {
  if (!ict()) return state.SkipWithError("../shared/data absent");
  SyntheticFaceScanOptions o;
  o.size_px = static_cast<int>(state.range(0));
  o.pixel_mm = 0.8 * 256.0 / o.size_px;
  const auto synthetic = render_synthetic_face_scan(*ict(), ict()->neutral_mm(), o);
  FaceLandmarks landmarks;
  landmarks.points_px = synthetic.landmarks.points_px;
  CleanOptions options;
  options.mask.method = state.range(1) ? GeodesicMethod::kHeat : GeodesicMethod::kFastMarching;
  state.SetLabel(state.range(1) ? "heat" : "fast marching");
  CleanStats stats;
  for (auto _ : state) {
    auto face = clean_scan(synthetic.scan, landmarks, options);
    if (!face.is_ok()) return state.SkipWithError(face.status().message().c_str());
    stats = face->stats;
  }
  state.counters["m_crop_ms"] = stats.mask_timing.crop_ms;
  state.counters["m_factor_ms"] = stats.mask_timing.factor_ms;
  state.counters["m_regions_ms"] = stats.mask_timing.regions_ms;
  state.counters["m_dist_ms"] = stats.mask_timing.distances_ms;
  state.counters["m_clip_ms"] = stats.mask_timing.clip_ms;
  state.counters["m_check_ms"] = stats.mask_timing.check_ms;
  state.counters["cropped_vertices"] = stats.cropped_vertices;
  state.counters["in_vertices"] = stats.input_vertices;
  state.counters["out_vertices"] = stats.output_vertices;
  state.counters["mesh_ms"] = stats.mesh_ms;
  state.counters["fill_ms"] = stats.fill_ms;
  state.counters["holes_filled"] = stats.holes_filled;
  state.counters["vertices_added"] = stats.vertices_added;
  state.counters["total_ms"] = stats.total_ms;
  state.counters["mask_ms"] = stats.mask_ms;
  state.counters["allocator_tuned"] = kAllocatorTuned;
}
// Args: image size (px; the face keeps its size in the image), geodesics (0: fast marching,
// 1: heat). 512 px gives about 148K vertices, 672 px about 255K.
BENCHMARK(BM_CleanScan)
    ->Args({256, 0})
    ->Args({256, 1})
    ->Args({512, 0})
    ->Args({512, 1})
    ->Args({672, 0})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// Heat geodesics: factorisation + one query on an n x n grid, both sparse back ends.
void BM_HeatGeodesics(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  Mesh mesh;
  std::vector<Mesh::VertexHandle> v;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) v.push_back(mesh.add_vertex(Mesh::Point(x, y, 0.002 * x * y)));
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      mesh.add_face(v[y * n + x], v[y * n + x + 1], v[(y + 1) * n + x + 1]);
      mesh.add_face(v[y * n + x], v[(y + 1) * n + x + 1], v[(y + 1) * n + x]);
    }
  HeatGeodesicsOptions options;
  options.solver = state.range(1) ? SparseSolverKind::kCholmod : SparseSolverKind::kSimplicialLdlt;
  for (auto _ : state) {
    HeatGeodesics geodesics(mesh, options);
    benchmark::DoNotOptimize(geodesics.distance({mesh.vertex_handle(0)}));
  }
  state.SetLabel(state.range(1) ? "cholmod" : "eigen-ldlt (reference)");
  state.counters["vertices"] = n * n;
}
BENCHMARK(BM_HeatGeodesics)
    ->Args({100, 1})
    ->Args({100, 0})
    ->Args({200, 1})
    ->Args({200, 0})
    ->Unit(benchmark::kMillisecond);

// Fast marching from one corner over an n x n grid (the whole of it): the heap with keys (the
// default) and its plain reference.
void BM_FastMarching(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  Mesh mesh;
  std::vector<Mesh::VertexHandle> v;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) v.push_back(mesh.add_vertex(Mesh::Point(x, y, 0.002 * x * y)));
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      mesh.add_face(v[y * n + x], v[y * n + x + 1], v[(y + 1) * n + x + 1]);
      mesh.add_face(v[y * n + x], v[(y + 1) * n + x + 1], v[(y + 1) * n + x]);
    }
  const FastMarching marching(mesh);
  for (auto _ : state)
    benchmark::DoNotOptimize(state.range(1) ? marching.distance_reference({v[0]})
                                            : marching.distance({v[0]}));
  state.SetLabel(state.range(1) ? "reference" : "heap with keys");
  state.counters["vertices"] = n * n;
}
BENCHMARK(BM_FastMarching)->Args({500, 0})->Args({500, 1})->Unit(benchmark::kMillisecond);

// Building a mesh from an n x n grid of points and its triangles (a scan's size at n = 500):
// the direct half-edge build (the default) and OpenMesh's add_face (the reference).
void BM_MeshFromTriangles(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::vector<Mesh::Point> points;
  std::vector<Mesh::Color> colors;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      points.emplace_back(x, y, 0.002 * x * y);
      colors.emplace_back(0.5f, 0.5f, 0.5f, 1.0f);
    }
  std::vector<std::array<int, 3>> triangles;
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      const int a = y * n + x, b = a + 1, c = a + n + 1, d = a + n;
      if (x % 97 == 40 && y % 89 == 30) continue;  // a few one-quad holes
      triangles.push_back({a, c, b});
      triangles.push_back({a, d, c});
    }
  MeshRepairOptions options;
  options.check_duplicates = false;
  options.direct_build = state.range(1) == 0;
  Mesh mesh;
  for (auto _ : state) {
    mesh_from_triangles(points, colors, triangles, options, &mesh, nullptr);
    benchmark::DoNotOptimize(mesh.n_halfedges());
  }
  state.SetLabel(state.range(1) ? "add_face (reference)" : "direct half-edge build");
  state.counters["vertices"] = static_cast<double>(mesh.n_vertices());
}
BENCHMARK(BM_MeshFromTriangles)->Args({500, 0})->Args({500, 1})->Unit(benchmark::kMillisecond);

// open_pinched_fans (mesh_from_scan's pinch opening) on an n x n grid: arg 1 = 0 without gaps
// (the check alone), else that many per mille of the pixels missing at random (each missing
// pixel's four quads lose their triangles, so gaps meet diagonally: the pinches of a noisy scan).
// Read against BM_MeshFromTriangles on the same size, which every scan pays anyway.
void BM_OpenPinchedFans(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::vector<Mesh::Point> points;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) points.emplace_back(x, y, 0.002 * x * y);
  std::vector<char> missing(points.size(), 0);
  cv::RNG rng(3);
  for (auto& m : missing) m = rng.uniform(0, 1000) < state.range(1);
  std::vector<std::array<int, 3>> triangles;
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      const int a = y * n + x, b = a + 1, c = a + n + 1, d = a + n;
      if (missing[a] || missing[b] || missing[c] || missing[d]) continue;
      triangles.push_back({a, c, b});
      triangles.push_back({a, d, c});
    }
  int removed = 0;
  for (auto _ : state) {
    std::vector<std::array<int, 3>> work = triangles;
    removed = open_pinched_fans(points, &work);
    benchmark::DoNotOptimize(work.data());
  }
  state.counters["triangles"] = static_cast<double>(triangles.size());
  state.counters["removed"] = removed;
}
BENCHMARK(BM_OpenPinchedFans)->Args({500, 0})->Args({500, 20})->Unit(benchmark::kMillisecond);

// Rim points mapped to the neutral face through the closest point on the frame's ICT face.
std::vector<Mesh::Point> rim_in_neutral(const Mesh& cleaned, const Mesh& frame_face,
                                        const Mesh& neutral_face) {
  std::vector<Mesh::Point> out;
  const auto loops = boundary_loops(cleaned);
  // The mask rim is the loop farthest from the face's centre, i.e. the longest in mm.
  size_t rim = 0;
  double best = -1;
  for (size_t k = 0; k < loops.size(); ++k) {
    double length = 0;
    for (size_t i = 0; i < loops[k].size(); ++i)
      length +=
          (cleaned.point(loops[k][i]) - cleaned.point(loops[k][(i + 1) % loops[k].size()])).norm();
    if (length > best) best = length, rim = k;
  }
  for (auto v : loops[rim]) {
    const Mesh::Point p = cleaned.point(v);
    double d_best = std::numeric_limits<double>::infinity();
    Mesh::Point mapped;
    for (auto f : frame_face.faces()) {
      std::array<Mesh::VertexHandle, 3> fv;
      int k = 0;
      for (auto w : frame_face.fv_range(f)) fv[k++] = w;
      const Mesh::Point a = frame_face.point(fv[0]), b = frame_face.point(fv[1]),
                        c = frame_face.point(fv[2]);
      const Mesh::Point q = closest_point_on_triangle(p, a, b, c);
      const double d = (q - p).sqrnorm();
      if (d >= d_best) continue;
      d_best = d;
      // Barycentric coordinates of q in (a, b, c), applied to the neutral triangle.
      const Mesh::Point v0 = b - a, v1 = c - a, v2 = q - a;
      const double d00 = v0 | v0, d01 = v0 | v1, d11 = v1 | v1, d20 = v2 | v0, d21 = v2 | v1;
      const double den = d00 * d11 - d01 * d01;
      const double wb = (d11 * d20 - d01 * d21) / den, wc = (d00 * d21 - d01 * d20) / den;
      mapped = neutral_face.point(fv[0]) * (1 - wb - wc) + neutral_face.point(fv[1]) * wb +
               neutral_face.point(fv[2]) * wc;
    }
    out.push_back(mapped);
  }
  return out;
}

double rms_to_polyline(const std::vector<Mesh::Point>& points,
                       const std::vector<Mesh::Point>& loop) {
  double sum = 0;
  for (const auto& p : points) {
    double best = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < loop.size(); ++i) {
      const Mesh::Point a = loop[i], b = loop[(i + 1) % loop.size()];
      const Mesh::Point ab = b - a;
      const double t = std::clamp(((p - a) | ab) / std::max(ab | ab, 1e-12), 0.0, 1.0);
      best = std::min(best, (p - (a + ab * t)).norm());
    }
    sum += best * best;
  }
  return std::sqrt(sum / points.size());
}

// Expression sequence on the ICT meshes (true landmarks): RMS movement of the mask rim.
void BM_MaskConsistency(benchmark::State& state) {
  if (!ict()) return state.SkipWithError("../shared/data absent");
  const IctFaceModel& m = *ict();
  CleanOptions options;
  options.mask.radius_factor = state.range(0) / 100.0;
  options.mask.method = state.range(1) ? GeodesicMethod::kHeat : GeodesicMethod::kFastMarching;
  state.SetLabel(state.range(1) ? "heat" : "fast marching");
  const std::vector<std::map<std::string, double>> sequence = {
      {},
      {{"jawOpen", 0.3}},
      {{"jawOpen", 0.6}},
      {{"mouthSmile_L", 0.8}, {"mouthSmile_R", 0.8}},
      {{"browInnerUp_L", 0.8}, {"browInnerUp_R", 0.8}},
      {{"eyeBlink_L", 1.0}, {"eyeBlink_R", 1.0}},
      {{"jawOpen", 0.4}, {"mouthSmile_L", 0.5}, {"mouthSmile_R", 0.5}}};
  const Mesh neutral_face = m.face_mesh(m.neutral_mm());
  // One radius for the whole sequence: the neutral frame's automatic radius.
  FaceLandmarks neutral_landmarks;
  for (int v : m.landmark_vertices()) neutral_landmarks.points_mm.emplace_back(m.neutral_mm()[v]);
  options.mask.radius_mm = default_mask_radius_mm(neutral_landmarks, options.mask.radius_factor);
  double worst = 0, sum = 0;
  int failed = 0;
  for (auto _ : state) {
    std::vector<Mesh::Point> reference;
    for (size_t k = 0; k < sequence.size(); ++k) {
      const auto positions = m.evaluate(sequence[k]);
      FaceLandmarks landmarks;
      for (int v : m.landmark_vertices()) landmarks.points_mm.emplace_back(positions[v]);
      const Mesh frame_face = m.face_mesh(positions);
      auto face = clean_mesh(frame_face, landmarks, "ict", options);
      if (!face.is_ok()) {
        std::fprintf(stderr, "frame %zu: %s\n", k, face.status().message().c_str());
        ++failed;
        continue;
      }
      const auto rim = rim_in_neutral(face->mesh, frame_face, neutral_face);
      if (k == 0) {
        reference = rim;
        continue;
      }
      const double rms = rms_to_polyline(rim, reference);
      std::fprintf(stderr, "radius factor %.2f, frame %zu: rim RMS %.2f mm\n",
                   options.mask.radius_factor, k, rms);
      worst = std::max(worst, rms);
      sum += rms;
    }
  }
  state.counters["radius_mm"] = options.mask.radius_mm;
  state.counters["mean_rim_rms_mm"] = sum / (sequence.size() - 1 - failed);
  state.counters["worst_rim_rms_mm"] = worst;
  state.counters["failed_frames"] = failed;
}
// Args: radius factor x 100, geodesics (0: fast marching, 1: heat).
BENCHMARK(BM_MaskConsistency)
    ->Args({70, 0})
    ->Args({80, 0})
    ->Args({80, 1})
    ->Args({100, 0})
    ->Args({100, 1})
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

// dlib landmarks on synthetic ICT renders: mean error (px) against the projected ICT landmark
// vertices, all 68, the inner 41 (27-67: nose, eyes, mouth) and per group; and the part of the
// error that is a constant offset per landmark over the renders (a difference of landmark
// conventions between the ICT vertices and dlib's annotations, not detection noise).
void BM_SyntheticLandmarks(benchmark::State& state) {
  if (!ict()) return state.SkipWithError("../shared/data absent");
  auto detector = LandmarkDetector::create();
  if (!detector.is_ok()) return state.SkipWithError(detector.status().message().c_str());
  SyntheticFaceScanOptions o;
  o.size_px = static_cast<int>(state.range(0));
  o.pixel_mm = 0.8 * 256.0 / o.size_px;
  const std::vector<std::map<std::string, double>> expressions = {
      {}, {{"jawOpen", 0.3}}, {{"mouthSmile_L", 0.8}, {"mouthSmile_R", 0.8}}};
  struct Group {
    const char* name;
    int first, last;
  };
  const Group groups[] = {{"jaw", 0, 16},    {"brows", 17, 26}, {"nose", 27, 35}, {"eyes", 36, 47},
                          {"mouth", 48, 67}, {"27_67", 27, 67}, {"all", 0, 67}};
  std::vector<std::vector<cv::Point2f>> errors;  // per detected render: detected - true
  for (auto _ : state) {
    for (const auto& e : expressions) {
      const auto synthetic = render_synthetic_face_scan(*ict(), ict()->evaluate(e), o);
      auto d = detector->detect(synthetic.scan.texture);
      if (!d.is_ok()) continue;
      std::vector<cv::Point2f> err(68);
      for (int i = 0; i < 68; ++i) err[i] = d->points_px[i] - synthetic.landmarks.points_px[i];
      errors.push_back(err);
    }
  }
  const int found = static_cast<int>(errors.size());
  state.counters["renders"] = static_cast<double>(expressions.size());
  state.counters["detected"] = found;
  if (found == 0) return;
  std::vector<cv::Point2f> bias(68, cv::Point2f(0, 0));
  for (const auto& err : errors)
    for (int i = 0; i < 68; ++i) bias[i] += err[i] / found;
  for (const auto& g : groups) {
    double mean = 0.0, offset = 0.0, residual = 0.0;
    const int n = (g.last - g.first + 1) * found;
    for (const auto& err : errors)
      for (int i = g.first; i <= g.last; ++i) {
        mean += cv::norm(err[i]) / n;
        offset += cv::norm(bias[i]) / n;
        residual += cv::norm(err[i] - bias[i]) / n;
      }
    state.counters[std::string("err_px_") + g.name] = mean;
    state.counters[std::string("offset_px_") + g.name] = offset;
    state.counters[std::string("resid_px_") + g.name] = residual;
  }
}
BENCHMARK(BM_SyntheticLandmarks)->Arg(256)->Arg(512)->Unit(benchmark::kSecond)->Iterations(1);

// dlib on its own example photographs (no independent ground truth): faces detected per photo.
void BM_DlibExamplePhotos(benchmark::State& state) {
  const std::filesystem::path dir = "/usr/share/doc/libdlib19.1/examples/faces";
  if (!std::filesystem::exists(dir)) return state.SkipWithError("dlib example photos absent");
  LandmarkDetectorOptions options;
  options.upsample = 1;
  auto detector = LandmarkDetector::create(options);
  if (!detector.is_ok()) return state.SkipWithError(detector.status().message().c_str());
  int photos = 0, with_face = 0, faces = 0;
  for (auto _ : state) {
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
      if (entry.path().extension() != ".jpg") continue;
      const cv::Mat image = cv::imread(entry.path().string(), cv::IMREAD_GRAYSCALE);
      ++photos;
      const auto boxes = detector->detect_faces(image);
      faces += static_cast<int>(boxes.size());
      with_face += !boxes.empty() && detector->detect(image).is_ok();
    }
  }
  state.counters["photos"] = photos;
  state.counters["photos_with_68_points"] = with_face;
  state.counters["faces_detected"] = faces;
}
BENCHMARK(BM_DlibExamplePhotos)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace gvkit::facemap

BENCHMARK_MAIN();
