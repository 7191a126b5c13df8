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
  auto unite = [&](Mesh::HalfedgeHandle h) {
    const int a = root(mesh.from_vertex_handle(h).idx()), b = root(mesh.to_vertex_handle(h).idx());
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  };
  if (mesh.has_halfedge_status()) {
    for (auto e : mesh.edges()) unite(mesh.halfedge_handle(e, 0));
    for (const auto& loop : boundary_loops(mesh))
      t.boundary_loop_lengths.push_back(static_cast<int>(loop.size()));
  } else {
    // One pass over the edges for the components and the boundary loops (the halfedges 2e and
    // 2e + 1 of each edge e in turn: the order of boundary_loops, which skips no halfedge here;
    // the edges skipped are those mesh.edges() skips). The loops are walked as in boundary_loops.
    const int n_halfedges = static_cast<int>(mesh.n_halfedges());
    std::vector<char> visited(n_halfedges, 0);
    const bool edge_status = mesh.has_edge_status();
    for (int e = 0; e < static_cast<int>(mesh.n_edges()); ++e) {
      const Mesh::EdgeHandle eh(e);
      if (!edge_status || !(mesh.status(eh).deleted() || mesh.status(eh).hidden()))
        unite(mesh.halfedge_handle(eh, 0));
      for (int k = 0; k < 2; ++k) {
        const Mesh::HalfedgeHandle start(2 * e + k);
        if (!mesh.is_boundary(start) || visited[start.idx()]) continue;
        int length = 0;
        auto h = start;
        for (int guard = 0; guard <= n_halfedges; ++guard) {
          if (visited[h.idx()]) break;
          visited[h.idx()] = 1;
          ++length;
          h = mesh.next_halfedge_handle(h);
        }
        t.boundary_loop_lengths.push_back(length);
      }
    }
    // Longest first, as boundary_loops orders them.
    std::stable_sort(t.boundary_loop_lengths.begin(), t.boundary_loop_lengths.end(),
                     [](int a, int b) { return a > b; });
  }
  for (auto v : mesh.vertices()) {
    if (mesh.is_isolated(v)) {
      ++t.isolated_vertices;
      continue;
    }
    if (root(v.idx()) == v.idx()) ++t.components;
  }
  t.vertices = static_cast<int>(mesh.n_vertices()) - t.isolated_vertices;
  t.boundary_loops = static_cast<int>(t.boundary_loop_lengths.size());
  t.euler_characteristic = t.vertices - t.edges + t.faces;
  if (t.components == 1) t.genus = (2 - t.euler_characteristic - t.boundary_loops) / 2;
  return t;
}

}  // namespace gvkit
