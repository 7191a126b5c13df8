#include "gvkit/facemap/mesh_repair.hpp"

#include <algorithm>
#include <mutex>
#include <numeric>
#include <set>

#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

bool MeshRepairReport::changed() const {
  return degenerate_faces + duplicate_faces + non_manifold_faces + removed_component_faces +
             removed_vertices >
         0;
}

std::string MeshRepairReport::summary() const {
  std::string s;
  auto add = [&](int n, const char* what) {
    if (n == 0) return;
    if (!s.empty()) s += ", ";
    s += std::to_string(n) + " " + what;
  };
  add(degenerate_faces, "degenerate faces removed");
  add(duplicate_faces, "duplicate faces removed");
  add(non_manifold_faces, "non-manifold faces removed");
  if (components > 1)
    add(removed_component_faces,
        ("faces in smaller components removed (" + std::to_string(components) + " components)")
            .c_str());
  add(removed_vertices, "unreferenced vertices removed");
  return s.empty() ? "no repair needed" : s;
}

namespace {

int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

Mesh mesh_from_triangles(const std::vector<Mesh::Point>& points,
                         const std::vector<Mesh::Color>& colors,
                         const std::vector<std::array<int, 3>>& triangles,
                         const MeshRepairOptions& options, MeshRepairReport* report,
                         std::vector<int>* original_index) {
  MeshRepairReport local;
  MeshRepairReport& r = report ? *report : local;
  r = {};
  const int n = static_cast<int>(points.size());

  // Degenerate and duplicate faces.
  // Duplicates by sorting (corner set, position): the first of equal corner sets is kept.
  std::vector<std::pair<std::array<int, 3>, int>> keys;
  keys.reserve(triangles.size());
  std::vector<char> drop(triangles.size(), 0);
  for (size_t i = 0; i < triangles.size(); ++i) {
    const auto& t = triangles[i];
    for (int k = 0; k < 3; ++k) GVKIT_CHECK(t[k] >= 0 && t[k] < n, "triangle index out of range");
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0] ||
        ((points[t[1]] - points[t[0]]) % (points[t[2]] - points[t[0]])).sqrnorm() == 0.0) {
      ++r.degenerate_faces;
      drop[i] = 1;
      continue;
    }
    std::array<int, 3> key = t;
    std::sort(key.begin(), key.end());
    keys.emplace_back(key, static_cast<int>(i));
  }
  std::sort(keys.begin(), keys.end());
  for (size_t k = 1; k < keys.size(); ++k)
    if (keys[k].first == keys[k - 1].first) {
      drop[keys[k].second] = 1;
      ++r.duplicate_faces;
    }
  std::vector<std::array<int, 3>> faces;
  faces.reserve(triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i)
    if (!drop[i]) faces.push_back(triangles[i]);

  // Components (union-find over face corners), keep the largest by face count.
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& t : faces) {
    const int a = find_root(parent, t[0]);
    parent[find_root(parent, t[1])] = a;
    parent[find_root(parent, t[2])] = a;
  }
  std::vector<int> faces_per_root(n, 0);
  for (const auto& t : faces) ++faces_per_root[find_root(parent, t[0])];
  r.components = static_cast<int>(
      std::count_if(faces_per_root.begin(), faces_per_root.end(), [](int c) { return c > 0; }));
  int keep_root = -1;
  if (options.keep_largest_component && r.components > 1)
    keep_root = static_cast<int>(std::max_element(faces_per_root.begin(), faces_per_root.end()) -
                                 faces_per_root.begin());

  // OpenMesh reports refused faces on its own stream; they are counted here instead.
  static std::once_flag silence;
  std::call_once(silence, [] { omerr().disable(); });
  Mesh mesh;
  mesh.reserve(n, 3 * faces.size() / 2 + n, faces.size());
  const bool with_colors = !colors.empty();
  GVKIT_CHECK(!with_colors || colors.size() == points.size(), "one colour per point");
  if (with_colors) mesh.request_vertex_colors();
  std::vector<Mesh::VertexHandle> handle(n);
  std::vector<int> original;
  for (const auto& t : faces) {
    if (keep_root >= 0 && find_root(parent, t[0]) != keep_root) {
      ++r.removed_component_faces;
      continue;
    }
    std::array<Mesh::VertexHandle, 3> fv;
    for (int k = 0; k < 3; ++k) {
      if (!handle[t[k]].is_valid()) {
        handle[t[k]] = mesh.add_vertex(points[t[k]]);
        if (with_colors) mesh.set_color(handle[t[k]], colors[t[k]]);
        original.push_back(t[k]);
      }
      fv[k] = handle[t[k]];
    }
    if (!mesh.add_face(fv[0], fv[1], fv[2]).is_valid()) ++r.non_manifold_faces;
  }
  // Vertices whose only faces were dropped.
  bool any_isolated = false;
  for (auto v : mesh.vertices())
    if (mesh.is_isolated(v)) {
      mesh.delete_vertex(v, false);
      any_isolated = true;
    }
  if (any_isolated) {
    // Track the original indices through garbage collection via a vertex property.
    OpenMesh::VPropHandleT<int> orig;
    mesh.add_property(orig);
    for (auto v : mesh.all_vertices()) mesh.property(orig, v) = original[v.idx()];
    mesh.garbage_collection();
    original.assign(mesh.n_vertices(), -1);
    for (auto v : mesh.vertices()) original[v.idx()] = mesh.property(orig, v);
    mesh.remove_property(orig);
  }
  r.removed_vertices = n - static_cast<int>(mesh.n_vertices());
  if (original_index) *original_index = std::move(original);
  return mesh;
}

MeshRepairReport repair_mesh(Mesh* mesh, const MeshRepairOptions& options) {
  std::vector<Mesh::Point> points;
  std::vector<Mesh::Color> colors;
  points.reserve(mesh->n_vertices());
  for (auto v : mesh->vertices()) points.push_back(mesh->point(v));
  if (mesh->has_vertex_colors())
    for (auto v : mesh->vertices()) colors.push_back(mesh->color(v));
  std::vector<std::array<int, 3>> triangles;
  triangles.reserve(mesh->n_faces());
  for (auto f : mesh->faces()) {
    std::array<int, 3> t;
    int k = 0;
    for (auto v : mesh->fv_range(f)) {
      if (k < 3) t[k] = v.idx();
      ++k;
    }
    if (k == 3) triangles.push_back(t);
  }
  MeshRepairReport report;
  *mesh = mesh_from_triangles(points, colors, triangles, options, &report);
  return report;
}

}  // namespace gvkit::facemap
