#pragma once
// Cutting a face mesh open: inserting path points as vertices (edge splits) and cutting along
// marked edges into a TriSurface. Inserted vertices interpolate position, colour, source weights
// and any number of scalar fields linearly.

#include <vector>

#include "gvkit/core/mesh.hpp"
#include "gvkit/facemap/descent_path.hpp"
#include "gvkit/facemap/tri_surface.hpp"

namespace gvkit::facemap {

// A mesh being cut, with the properties that follow every edge split.
struct CuttableMesh {
  Mesh mesh;
  OpenMesh::VPropHandleT<SourceWeights> source;
  std::vector<OpenMesh::VPropHandleT<double>> fields;

  // Copies mesh; every vertex's source is itself with weight 1, or vertex source_index[v] of
  // another mesh (mesh is a trimmed copy of it) when source_index is given.
  explicit CuttableMesh(const Mesh& input, const std::vector<int>* source_index = nullptr);
  CuttableMesh(const CuttableMesh&) = delete;
  CuttableMesh& operator=(const CuttableMesh&) = delete;
  // Adds a scalar field (one value per current vertex); returns its index in fields.
  int add_field(const std::vector<double>& values);
  std::vector<double> field(int index) const;
};

// Splits the edge of halfedge h at t (0 at from_vertex) and returns the new vertex.
Mesh::VertexHandle split_edge_at(CuttableMesh& cm, Mesh::HalfedgeHandle h, double t);

// Inserts the points of a path (from trace_descent_path on cm.mesh) as vertices and returns the
// path's vertices in order; consecutive vertices are joined by an edge. A path that crosses an
// edge twice is a contract error.
std::vector<Mesh::VertexHandle> insert_path(CuttableMesh& cm,
                                            const std::vector<SurfacePoint>& path);

// Cuts cm.mesh open along the given edges (edge_is_cut indexed by edge index): vertices on cut
// edges are duplicated once per fan sector. Returns the cut surface; uncut_vertex maps each of
// its vertices back to the vertex index of cm.mesh.
TriSurface cut_along_edges(const CuttableMesh& cm, const std::vector<char>& edge_is_cut);

}  // namespace gvkit::facemap
