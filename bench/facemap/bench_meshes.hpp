#pragma once
// Shared material of the facemap peer benchmarks: the ICT and Spacetime faces (holes filled),
// conversion to CGAL's Surface_mesh, and hole punching with the removed true points.
#include <filesystem>
#include <optional>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "gvkit/facemap/hole_filling.hpp"

namespace gvkit::facemap::bench {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

inline std::filesystem::path data_dir() { return GVKIT_SHARED_DATA_DIR; }

// The neutral ICT face with its eye and mouth holes filled, or nothing without shared data.
inline std::optional<Mesh> ict_face() {
  auto model = IctFaceModel::load(data_dir() / "ict-facekit", {"jawOpen"});
  if (!model.is_ok()) return std::nullopt;
  Mesh mesh = model->face_mesh(model->neutral_mm());
  if (!fill_holes(&mesh).is_ok()) return std::nullopt;
  return mesh;
}

inline std::optional<Mesh> spacetime_face() {
  auto mesh = read_mesh(data_dir() / "spacetime-faces" / "neutral.ply");
  if (!mesh.is_ok()) return std::nullopt;
  Mesh m = std::move(mesh).value();
  if (!fill_holes(&m).is_ok()) return std::nullopt;
  return m;
}

inline SurfaceMesh to_cgal(const Mesh& mesh) {
  SurfaceMesh sm;
  std::vector<SurfaceMesh::Vertex_index> v;
  for (auto h : mesh.vertices()) {
    const auto& p = mesh.point(h);
    v.push_back(sm.add_vertex(Kernel::Point_3(p[0], p[1], p[2])));
  }
  for (auto f : mesh.faces()) {
    std::vector<SurfaceMesh::Vertex_index> fv;
    for (auto w : mesh.fv_range(f)) fv.push_back(v[w.idx()]);
    sm.add_face(fv[0], fv[1], fv[2]);
  }
  return sm;
}

inline Mesh::Point nearest_vertex_point(const Mesh& mesh, const Mesh::Point& p) {
  Mesh::Point best = mesh.point(mesh.vertex_handle(0));
  for (auto v : mesh.vertices())
    if ((mesh.point(v) - p).norm() < (best - p).norm()) best = mesh.point(v);
  return best;
}

// Removes the faces with a vertex within radius_mm of center (a surface point); returns the
// removed vertices' true positions.
inline std::vector<Mesh::Point> punch_hole(Mesh* mesh, const Mesh::Point& center,
                                           double radius_mm) {
  std::vector<Mesh::Point> removed;
  for (auto f : mesh->faces()) {
    bool inside = false;
    for (auto v : mesh->fv_range(f)) inside |= (mesh->point(v) - center).norm() < radius_mm;
    if (inside) mesh->delete_face(f, false);
  }
  for (auto v : mesh->vertices())
    if (mesh->is_isolated(v)) {
      removed.push_back(mesh->point(v));
      mesh->delete_vertex(v, false);
    }
  mesh->garbage_collection();
  return removed;
}

}  // namespace gvkit::facemap::bench
