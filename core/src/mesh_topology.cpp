#include "gvkit/core/mesh_topology.hpp"

#include <algorithm>
#include <numeric>

namespace gvkit {

std::vector<std::vector<Mesh::VertexHandle>> boundary_loops(const Mesh& mesh) {
  std::vector<std::vector<Mesh::VertexHandle>> loops;
  std::vector<char> visited(mesh.n_halfedges(), 0);
  for (auto start : mesh.halfedges()) {
    if (!mesh.is_boundary(start) || visited[start.idx()]) continue;
    std::vector<Mesh::VertexHandle> loop;
    auto h = start;
    // A boundary halfedge's next is the next boundary halfedge of the same loop. The guard
    // bounds the walk on non-manifold input, where next() may not return to start.
    for (size_t guard = 0; guard <= mesh.n_halfedges(); ++guard) {
      if (visited[h.idx()]) break;
      visited[h.idx()] = 1;
      loop.push_back(mesh.from_vertex_handle(h));
      h = mesh.next_halfedge_handle(h);
    }
    loops.push_back(std::move(loop));
  }
  std::stable_sort(loops.begin(), loops.end(),
                   [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return loops;
}

MeshTopology mesh_topology(const Mesh& mesh) {
  MeshTopology t;
  t.faces = static_cast<int>(mesh.n_faces());
  t.edges = static_cast<int>(mesh.n_edges());
  // Components: union-find over the edges' end vertices (isolated vertices are not counted).
  std::vector<int> parent(mesh.n_vertices());
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&parent](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    const int a = root(mesh.from_vertex_handle(h).idx()), b = root(mesh.to_vertex_handle(h).idx());
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  for (auto v : mesh.vertices()) {
    if (mesh.is_isolated(v)) {
      ++t.isolated_vertices;
      continue;
    }
    if (root(v.idx()) == v.idx()) ++t.components;
  }
  t.vertices = static_cast<int>(mesh.n_vertices()) - t.isolated_vertices;
  for (const auto& loop : boundary_loops(mesh))
    t.boundary_loop_lengths.push_back(static_cast<int>(loop.size()));
  t.boundary_loops = static_cast<int>(t.boundary_loop_lengths.size());
  t.euler_characteristic = t.vertices - t.edges + t.faces;
  if (t.components == 1) t.genus = (2 - t.euler_characteristic - t.boundary_loops) / 2;
  return t;
}

}  // namespace gvkit
