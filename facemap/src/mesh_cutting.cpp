#include "gvkit/facemap/mesh_cutting.hpp"

#include <map>
#include <numeric>

#include "directed_edges.hpp"

namespace gvkit::facemap {

SourceWeights interpolate_source_weights(const SourceWeights& a, const SourceWeights& b, double t) {
  std::map<int, double> sum;
  for (const SourceWeight& w : a) sum[w.vertex] += (1.0 - t) * w.weight;
  for (const SourceWeight& w : b) sum[w.vertex] += t * w.weight;
  SourceWeights out;
  for (const auto& [v, w] : sum)
    if (w != 0) out.push_back({v, w});
  return out;
}

CuttableMesh::CuttableMesh(const Mesh& input, const std::vector<int>* source_index) : mesh(input) {
  mesh.add_property(source);
  GVKIT_CHECK(!source_index || source_index->size() == mesh.n_vertices());
  for (auto v : mesh.vertices())
    mesh.property(source, v) = {{source_index ? (*source_index)[v.idx()] : v.idx(), 1.0}};
}

int CuttableMesh::add_field(const std::vector<double>& values) {
  GVKIT_CHECK(values.size() == mesh.n_vertices());
  OpenMesh::VPropHandleT<double> handle;
  mesh.add_property(handle);
  for (auto v : mesh.vertices()) mesh.property(handle, v) = values[v.idx()];
  fields.push_back(handle);
  return static_cast<int>(fields.size()) - 1;
}

std::vector<double> CuttableMesh::field(int index) const {
  std::vector<double> out(mesh.n_vertices());
  for (auto v : mesh.vertices()) out[v.idx()] = mesh.property(fields.at(index), v);
  return out;
}

Mesh::VertexHandle split_edge_at(CuttableMesh& cm, Mesh::HalfedgeHandle h, double t) {
  Mesh& mesh = cm.mesh;
  const Mesh::VertexHandle a = mesh.from_vertex_handle(h), b = mesh.to_vertex_handle(h);
  const Mesh::VertexHandle v = mesh.add_vertex(mesh.point(a) * (1.0 - t) + mesh.point(b) * t);
  if (mesh.has_vertex_colors())
    mesh.set_color(
        v, mesh.color(a) * static_cast<float>(1.0 - t) + mesh.color(b) * static_cast<float>(t));
  mesh.property(cm.source, v) =
      interpolate_source_weights(mesh.property(cm.source, a), mesh.property(cm.source, b), t);
  for (const auto& field : cm.fields)
    mesh.property(field, v) = (1.0 - t) * mesh.property(field, a) + t * mesh.property(field, b);
  mesh.split(mesh.edge_handle(h), v);
  return v;
}

std::vector<Mesh::VertexHandle> insert_path(CuttableMesh& cm,
                                            const std::vector<SurfacePoint>& path) {
  std::vector<char> split_edge(cm.mesh.n_edges(), 0);
  std::vector<Mesh::VertexHandle> vertices;
  for (const SurfacePoint& p : path) {
    Mesh::VertexHandle v = p.vertex;
    if (!p.is_vertex()) {
      const int e = cm.mesh.edge_handle(p.halfedge).idx();
      GVKIT_CHECK(!split_edge[e], "a path crosses one edge twice");
      split_edge[e] = 1;
      v = split_edge_at(cm, p.halfedge, p.t);
    }
    if (vertices.empty() || vertices.back() != v) vertices.push_back(v);
  }
  return vertices;
}

namespace {

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

}  // namespace

TriSurface cut_along_edges(const CuttableMesh& cm, const std::vector<char>& edge_is_cut) {
  const Mesh& mesh = cm.mesh;
  GVKIT_CHECK(edge_is_cut.size() == mesh.n_edges());
  // Corner (face f, slot k) of face f's k-th vertex; corners meeting at a vertex across an uncut
  // interior edge belong to the same copy of that vertex.
  const size_t n_faces = mesh.n_faces();
  auto corner_of = [&](Mesh::FaceHandle f, Mesh::VertexHandle v) {
    int k = 0;
    for (auto fv : mesh.fv_range(f)) {
      if (fv == v) return static_cast<int>(f.idx()) * 3 + k;
      ++k;
    }
    GVKIT_CHECK(false, "vertex not in face");
    return -1;
  };
  UnionFind corners(n_faces * 3);
  for (auto e : mesh.edges()) {
    if (mesh.is_boundary(e) || edge_is_cut[e.idx()]) continue;
    const auto h = mesh.halfedge_handle(e, 0), o = mesh.halfedge_handle(e, 1);
    const auto f0 = mesh.face_handle(h), f1 = mesh.face_handle(o);
    for (auto v : {mesh.from_vertex_handle(h), mesh.to_vertex_handle(h)})
      corners.unite(corner_of(f0, v), corner_of(f1, v));
  }
  TriSurface out;
  std::vector<int> copy_of_root(n_faces * 3, -1);
  const bool colours = mesh.has_vertex_colors();
  out.triangles.reserve(n_faces);
  for (auto f : mesh.faces()) {
    std::array<int, 3> tri{};
    int k = 0;
    for (auto v : mesh.fv_range(f)) {
      const int root = corners.find(f.idx() * 3 + k);
      if (copy_of_root[root] < 0) {
        copy_of_root[root] = out.n_vertices();
        const auto& p = mesh.point(v);
        out.xyz.emplace_back(p[0], p[1], p[2]);
        if (colours) {
          const auto& c = mesh.color(v);
          out.colour.emplace_back(c[0], c[1], c[2], c[3]);
        }
        out.source.push_back(mesh.property(cm.source, v));
        out.uncut_vertex.push_back(v.idx());
      }
      tri[k++] = copy_of_root[root];
    }
    out.triangles.push_back(tri);
  }
  return out;
}

std::vector<std::vector<int>> tri_surface_boundary_loops(const TriSurface& surface) {
  // Directed boundary edges: (a -> b) of a triangle whose reverse (b -> a) is in no triangle.
  const DirectedEdges directed(surface.triangles, surface.n_vertices());
  std::vector<int> next(surface.n_vertices(), -1);
  for (int a = 0; a < surface.n_vertices(); ++a)
    for (int i = directed.begin(a); i < directed.end(a); ++i) {
      const int b = directed.to(i);
      GVKIT_CHECK(directed.count(a, b) == 1, "non-manifold edge in a TriSurface");
      if (directed.corner(b, a) < 0) {
        GVKIT_CHECK(next[a] < 0, "non-manifold boundary vertex in a TriSurface");
        next[a] = b;
      }
    }
  std::vector<std::vector<int>> loops;
  std::vector<char> seen(surface.n_vertices(), 0);
  for (int v = 0; v < surface.n_vertices(); ++v) {
    if (next[v] < 0 || seen[v]) continue;
    std::vector<int> loop;
    for (int x = v; !seen[x]; x = next[x]) {
      GVKIT_CHECK(next[x] >= 0, "open boundary chain");
      seen[x] = 1;
      loop.push_back(x);
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

}  // namespace gvkit::facemap
