// facemap per frame: the clean stage and the map stage of one synthetic ICT scan back to back,
// single thread, as the pipeline runs them (the canonical domain is made once per video, before
// the loop). The scan is the clean bench's: an orthographic render of the neutral ICT face at
// size x size px (672 px: 255,070 input vertices, about 247K after cleaning), true landmarks.
// CPU time is the figure to read; the counters are the steps' wall times (ms).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <optional>

#include "gvkit/core/allocator_tuning.hpp"
#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/facemap/canonical_domain.hpp"
#include "gvkit/facemap/eip_map.hpp"
#include "gvkit/facemap/face_cleaning.hpp"
#include "gvkit/facemap/synthetic_face_scan.hpp"

namespace gvkit::facemap {
namespace {

// The heap settings of the gvkit program (tools/main.cpp), so the times are those of its frames.
const bool kAllocatorTuned = tune_allocator_for_frames();

const IctFaceModel* ict() {
  static const IctFaceModel* model = [] {
    auto m = IctFaceModel::load(std::filesystem::path(GVKIT_SHARED_DATA_DIR) / "ict-facekit",
                                {"jawOpen"});
    return m.is_ok() ? new IctFaceModel(std::move(m).value()) : nullptr;
  }();
  return model;
}

const CanonicalDomain* domain() {
  static const CanonicalDomain* d = []() -> const CanonicalDomain* {
    auto spec = CanonicalDomainSpec::load_default();
    if (!spec.is_ok()) return nullptr;
    auto made = CanonicalDomain::create(*spec, {320, 320});
    return made.is_ok() ? new CanonicalDomain(std::move(made).value()) : nullptr;
  }();
  return d;
}

const SyntheticFaceScan* scan(int size_px) {
  static std::map<int, SyntheticFaceScan> cache;
  auto it = cache.find(size_px);
  if (it == cache.end()) {
    SyntheticFaceScanOptions o;
    o.size_px = size_px;
    o.pixel_mm = 0.8 * 256.0 / o.size_px;
    it = cache.emplace(size_px, render_synthetic_face_scan(*ict(), ict()->neutral_mm(), o)).first;
  }
  return &it->second;
}

// range(0): scan size (px); range(1): 0 = clean + map, 1 = clean only, 2 = map only (of the
// cleaned face, cleaned once before the loop).
void BM_CleanAndMap(benchmark::State& state) {
  if (!ict()) return state.SkipWithError("../shared/data absent");
  if (!domain()) return state.SkipWithError("no canonical domain");
  const SyntheticFaceScan* synthetic = scan(static_cast<int>(state.range(0)));
  FaceLandmarks landmarks;
  landmarks.points_px = synthetic->landmarks.points_px;
  const int what = static_cast<int>(state.range(1));
  std::optional<CleanedFace> cleaned_once;
  if (what == 2) {
    auto face = clean_scan(synthetic->scan, landmarks);
    if (!face.is_ok()) return state.SkipWithError(face.status().message().c_str());
    cleaned_once = std::move(face).value();
  }
  const auto distance = heat_geodesic_distance();
  CleanStats clean_stats;
  MappedFace mapped;
  for (auto _ : state) {
    const CleanedFace* face = cleaned_once ? &*cleaned_once : nullptr;
    std::optional<CleanedFace> cleaned;
    if (!face) {
      auto c = clean_scan(synthetic->scan, landmarks);
      if (!c.is_ok()) return state.SkipWithError(c.status().message().c_str());
      cleaned = std::move(c).value();
      face = &*cleaned;
    }
    clean_stats = face->stats;
    if (what == 1) continue;
    auto m = map_face_eip(face->mesh, face->landmarks, *domain(), distance);
    if (!m.is_ok()) return state.SkipWithError(m.status().message().c_str());
    mapped = std::move(m).value();
  }
  state.SetLabel(what == 0 ? "clean + map" : what == 1 ? "clean" : "map");
  state.counters["in_vertices"] = clean_stats.input_vertices;
  state.counters["face_vertices"] = clean_stats.output_vertices;
  if (what != 2) {
    state.counters["clean_ms"] = clean_stats.total_ms;
    state.counters["c_mesh_ms"] = clean_stats.mesh_ms;
    state.counters["c_fill_ms"] = clean_stats.fill_ms;
    state.counters["c_mask_ms"] = clean_stats.mask_ms;
  }
  if (what != 1) {
    const auto& t = mapped.timing;
    state.counters["map_ms"] = t.total_ms;
    state.counters["m_annulus_ms"] = t.annulus_ms;
    state.counters["m_cut_dist_ms"] = t.cut_distance_ms;
    state.counters["m_laplacian_ms"] = t.laplacian_ms;
    state.counters["m_order_ms"] = t.order_ms;
    state.counters["m_f_ms"] = t.f_ms;
    state.counters["m_psi_ms"] = t.psi_ms;
    state.counters["m_s_ms"] = t.correspondence_ms;
    state.counters["m_untangle_ms"] = t.untangle_ms;
    state.counters["m_resample_ms"] = t.resample_ms;
    state.counters["m_landmarks_ms"] = t.landmarks_ms;
    state.counters["m_quality_ms"] = t.quality_ms;
    state.counters["flips"] = mapped.st_flipped;
    state.counters["untangled"] = mapped.st_untangled;
  }
  state.counters["allocator_tuned"] = kAllocatorTuned;
}
BENCHMARK(BM_CleanAndMap)
    ->ArgsProduct({{256, 512, 672}, {0, 1, 2}})
    ->ArgNames({"px", "steps"})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gvkit::facemap

BENCHMARK_MAIN();
