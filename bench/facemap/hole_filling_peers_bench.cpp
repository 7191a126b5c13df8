// Hole filling against CGAL's triangulate_refine_and_fair_hole (C1 fairing): holes punched into
// the ICT and Spacetime faces, time and RMS deviation (mm) of the removed true vertices from the
// filled surface.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <set>

#include <CGAL/Polygon_mesh_processing/fair.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>

#include "bench_meshes.hpp"
#include "gvkit/facemap/surface_distance.hpp"

namespace gvkit::facemap::bench {
namespace {

struct Case {
  Mesh mesh;  // with the hole
  std::vector<Mesh::Point> removed;
};

// The mesh with every border but the longest filled by CGAL's triangulate_refine_and_fair_hole
// (new vertices appended), or nothing when a fill fails.
std::optional<Mesh> filled_by_cgal(const Mesh& mesh) {
  SurfaceMesh sm = to_cgal(mesh);
  std::vector<std::pair<size_t, SurfaceMesh::Halfedge_index>> borders;
  std::set<SurfaceMesh::Halfedge_index> seen;
  for (auto h : sm.halfedges()) {
    if (!sm.is_border(h) || seen.count(h)) continue;
    size_t n = 0;
    for (auto g : CGAL::halfedges_around_face(h, sm)) {
      seen.insert(g);
      ++n;
    }
    borders.emplace_back(n, h);
  }
  std::sort(borders.begin(), borders.end());
  for (size_t i = 0; i + 1 < borders.size(); ++i) {
    std::vector<SurfaceMesh::Face_index> faces;
    std::vector<SurfaceMesh::Vertex_index> vertices;
    if (!std::get<0>(CGAL::Polygon_mesh_processing::triangulate_refine_and_fair_hole(
            sm, borders[i].second, std::back_inserter(faces), std::back_inserter(vertices))))
      return std::nullopt;
  }
  Mesh out;
  std::vector<Mesh::VertexHandle> vh;
  for (auto v : sm.vertices()) {
    const auto& p = sm.point(v);
    vh.push_back(out.add_vertex(Mesh::Point(p.x(), p.y(), p.z())));
  }
  for (auto f : sm.faces()) {
    std::vector<Mesh::VertexHandle> fv;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) fv.push_back(vh[v.idx()]);
    out.add_face(fv[0], fv[1], fv[2]);
  }
  return out;
}

// Holes: 0 ICT cheek 12 mm, 1 ICT forehead 15 mm, 2 Spacetime cheek 10 mm, 3 Spacetime 15 mm,
// 4 ICT side of the nose 8 mm, 5 ICT chin below the lower lip 8 mm, 6 ICT cheek 22 mm,
// 7 Spacetime 22 mm, 8 ICT cheek 12 mm between the jaw landmark 3 and the nose landmark 31 (the
// hole of hole_filling_test). The Spacetime centres are offsets from the centroid of the captured
// vertices (before any fill), and the capture's own interior hole (next to hole 2) is filled by
// CGAL, not by the fill being measured, and the truth is the captured vertices only.
constexpr int kHoles = 9;
const Case* hole_case(int k) {
  static std::vector<std::optional<Case>> cases = [] {
    std::vector<std::optional<Case>> out(kHoles);
    auto make = [](const Mesh& base, const Mesh::Point& near, double r) {
      Case c{base, {}};
      c.removed = punch_hole(&c.mesh, nearest_vertex_point(c.mesh, near), r);
      return c;
    };
    auto ict = ict_face();
    auto model = IctFaceModel::load(data_dir() / "ict-facekit", {"jawOpen"});
    if (ict && model.is_ok()) {
      const auto& lm = model->landmark_vertices();
      auto landmark = [&](int i) {
        const cv::Vec3d p = model->neutral_mm()[lm[i]];
        return Mesh::Point(p[0], p[1], p[2]);
      };
      out[0] = make(*ict, Mesh::Point(-45, -5, 95), 12.0);
      out[1] = make(*ict, Mesh::Point(0, 70, 105), 15.0);
      out[4] = make(*ict, 0.5 * (landmark(29) + landmark(31)), 8.0);
      out[5] = make(*ict, 0.5 * (landmark(57) + landmark(8)), 8.0);
      out[6] = make(*ict, Mesh::Point(-45, -5, 95), 22.0);
      out[8] = make(*ict, 0.5 * (landmark(3) + landmark(31)), 12.0);
    }
    auto raw = read_mesh(data_dir() / "spacetime-faces" / "neutral.ply");
    if (raw.is_ok()) {
      const std::optional<Mesh> st = filled_by_cgal(*raw);
      Mesh::Point c(0, 0, 0);
      for (auto v : raw->vertices()) c += raw->point(v);
      c /= static_cast<double>(raw->n_vertices());
      std::set<std::array<double, 3>> captured;
      for (auto v : raw->vertices()) {
        const auto& p = raw->point(v);
        captured.insert({p[0], p[1], p[2]});
      }
      auto make_captured = [&](const Mesh::Point& near, double r) {
        Case k = make(*st, near, r);
        std::erase_if(k.removed, [&](const Mesh::Point& p) {
          return !captured.count({p[0], p[1], p[2]});
        });
        return k;
      };
      out[2] = make_captured(c + Mesh::Point(30, 0, 0), 10.0);
      out[3] = make_captured(c + Mesh::Point(-25, -30, 0), 15.0);
      out[7] = make_captured(c + Mesh::Point(-25, -30, 0), 22.0);
    }
    return out;
  }();
  return cases[k] ? &*cases[k] : nullptr;
}

double rms(const Mesh& mesh, const std::vector<Mesh::FaceHandle>& patch,
           const std::vector<Mesh::Point>& removed) {
  double sum = 0;
  for (const auto& p : removed) {
    const double d = distance_to_faces(mesh, patch, p);
    sum += d * d;
  }
  return std::sqrt(sum / removed.size());
}

void BM_OurFill(benchmark::State& state) {
  const Case* c = hole_case(static_cast<int>(state.range(0)));
  if (!c) return state.SkipWithError("../shared/data absent");
  Mesh filled;
  HoleFillingOptions options;
  options.density_factor = state.range(1) / 10.0;
  options.continuity = static_cast<int>(state.range(2));
  for (auto _ : state) {
    filled = c->mesh;
    auto report = fill_holes(&filled, options);
    if (!report.is_ok()) return state.SkipWithError(report.status().message().c_str());
  }
  std::vector<Mesh::FaceHandle> patch;
  for (auto f : filled.faces())
    if (f.idx() >= static_cast<int>(c->mesh.n_faces())) patch.push_back(f);
  state.counters["rms_mm"] = rms(filled, patch, c->removed);
  state.counters["removed"] = static_cast<double>(c->removed.size());
  state.counters["new_vertices"] = static_cast<double>(filled.n_vertices() - c->mesh.n_vertices());
}
// Args: hole, density factor x 10, continuity (the default: 8, 2; before 2026-12-02: 8, 1).
BENCHMARK(BM_OurFill)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5, 6, 7, 8}, {8, 10}, {1, 2}})
    ->Unit(benchmark::kMillisecond);

// The eye and mouth holes of the ICT face (what the clean stage fills on every frame), default
// options.
void BM_OurFillIctEyesAndMouth(benchmark::State& state) {
  auto model = IctFaceModel::load(data_dir() / "ict-facekit", {"jawOpen"});
  if (!model.is_ok()) return state.SkipWithError("../shared/data absent");
  const Mesh face = model->face_mesh(model->neutral_mm());
  Mesh filled;
  for (auto _ : state) {
    filled = face;
    auto report = fill_holes(&filled);
    if (!report.is_ok()) return state.SkipWithError(report.status().message().c_str());
    state.counters["holes"] = report->holes_filled;
  }
  state.counters["new_vertices"] = static_cast<double>(filled.n_vertices() - face.n_vertices());
}
BENCHMARK(BM_OurFillIctEyesAndMouth)->Unit(benchmark::kMillisecond);

void BM_CgalFairOnOurs(benchmark::State& state) {
  const Case* c = hole_case(static_cast<int>(state.range(0)));
  const int continuity = static_cast<int>(state.range(1));
  if (!c) return state.SkipWithError("../shared/data absent");
  Mesh filled = c->mesh;
  HoleFillingOptions options;
  options.continuity = continuity;
  auto report = fill_holes(&filled, options);
  SurfaceMesh sm = to_cgal(filled);
  std::vector<SurfaceMesh::Vertex_index> nv;
  for (auto v : sm.vertices())
    if (v.idx() >= c->mesh.n_vertices()) nv.push_back(v);
  for (auto _ : state) {
    SurfaceMesh s2 = sm;
    CGAL::Polygon_mesh_processing::fair(s2, nv, CGAL::parameters::fairing_continuity(continuity));
    for (auto v : nv) {
      const auto& p = s2.point(v);
      filled.set_point(filled.vertex_handle(v.idx()), Mesh::Point(p.x(), p.y(), p.z()));
    }
  }
  std::vector<Mesh::FaceHandle> patch;
  for (auto f : filled.faces())
    if (f.idx() >= static_cast<int>(c->mesh.n_faces())) patch.push_back(f);
  state.counters["rms_mm"] = rms(filled, patch, c->removed);
}
// Args: hole, continuity (of our fill, and of CGAL's fair() on its patch).
BENCHMARK(BM_CgalFairOnOurs)
    ->ArgsProduct({benchmark::CreateDenseRange(0, kHoles - 1, 1), {1, 2}})
    ->Unit(benchmark::kMillisecond);

void BM_CgalFill(benchmark::State& state) {
  const Case* c = hole_case(static_cast<int>(state.range(0)));
  if (!c) return state.SkipWithError("../shared/data absent");
  SurfaceMesh sm;
  std::vector<SurfaceMesh::Face_index> new_faces;
  size_t new_vertices = 0;
  for (auto _ : state) {
    sm = to_cgal(c->mesh);
    new_faces.clear();
    // The hole: the shorter border (the outer rim is the longest).
    SurfaceMesh::Halfedge_index hole;
    size_t best = std::numeric_limits<size_t>::max();
    std::set<SurfaceMesh::Halfedge_index> seen;
    for (auto h : sm.halfedges()) {
      if (!sm.is_border(h) || seen.count(h)) continue;
      size_t n = 0;
      for (auto g : CGAL::halfedges_around_face(h, sm)) {
        seen.insert(g);
        ++n;
      }
      if (n < best) best = n, hole = h;
    }
    std::vector<SurfaceMesh::Vertex_index> vertices;
    CGAL::Polygon_mesh_processing::triangulate_refine_and_fair_hole(
        sm, hole, std::back_inserter(new_faces), std::back_inserter(vertices),
        CGAL::parameters::fairing_continuity(static_cast<unsigned>(state.range(1))));
    new_vertices = vertices.size();
  }
  // Back to our mesh type for the same distance code.
  Mesh filled;
  std::vector<Mesh::VertexHandle> vh;
  for (auto v : sm.vertices()) {
    const auto& p = sm.point(v);
    vh.push_back(filled.add_vertex(Mesh::Point(p.x(), p.y(), p.z())));
  }
  std::vector<Mesh::FaceHandle> patch;
  for (auto f : new_faces) {
    std::vector<Mesh::VertexHandle> fv;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) fv.push_back(vh[v.idx()]);
    patch.push_back(filled.add_face(fv[0], fv[1], fv[2]));
  }
  state.counters["rms_mm"] = rms(filled, patch, c->removed);
  state.counters["removed"] = static_cast<double>(c->removed.size());
  state.counters["new_vertices"] = static_cast<double>(new_vertices);
}
// Args: hole, CGAL's fairing continuity (1: its default).
BENCHMARK(BM_CgalFill)
    ->ArgsProduct({benchmark::CreateDenseRange(0, kHoles - 1, 1), {1, 2}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gvkit::facemap::bench

BENCHMARK_MAIN();
