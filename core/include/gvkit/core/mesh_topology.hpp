#pragma once
// Topological facts of a triangle mesh: connected components, boundary loops, Euler
// characteristic and genus. Used by `gvkit info` and by facemap to verify its output.

#include <vector>

#include "gvkit/core/mesh.hpp"

namespace gvkit {

struct MeshTopology {
  int vertices = 0, edges = 0, faces = 0;
  int components = 0;  // connected by edges (isolated vertices are not counted)
  int boundary_loops = 0;
  int isolated_vertices = 0;
  int euler_characteristic = 0;  // V - E + F over non-isolated vertices
  // Genus of a single connected orientable component: (2 - chi - b) / 2; -1 if several components.
  int genus = -1;
  std::vector<int> boundary_loop_lengths;  // edges per loop, longest first
};

MeshTopology mesh_topology(const Mesh& mesh);

// Boundary loops as ordered vertex lists, longest (by edge count) first.
std::vector<std::vector<Mesh::VertexHandle>> boundary_loops(const Mesh& mesh);

}  // namespace gvkit
