#pragma once
// Shortest paths along mesh edges (Dijkstra, edge lengths in mm) between pairs of vertices, as
// the face mask traces the closed edge path through an eye's or the mouth's contour landmarks.
// Vertices are settled in order of (distance, index) and a vertex keeps the first predecessor
// that reached its final distance, so ties resolve the same way in the reference below.

#include <vector>

#include "gvkit/core/mesh.hpp"

namespace gvkit::facemap {

// Keeps per-vertex distance and predecessor arrays across queries on one mesh, so each query
// costs only the vertices it reaches (the arrays are reset where they were touched). The mesh
// must outlive the object and not change.
class ShortestEdgePaths {
 public:
  explicit ShortestEdgePaths(const Mesh& mesh);

  // The vertices of a shortest edge path from a to b, a first and b last; {a} when a == b;
  // empty when b cannot be reached from a. a and b must be valid vertices (contract).
  std::vector<Mesh::VertexHandle> path(Mesh::VertexHandle a, Mesh::VertexHandle b);

 private:
  const Mesh* mesh_;
  std::vector<double> distance_;
  std::vector<int> previous_;
  std::vector<int> touched_;
};

// The plain reference: the same search with a hash map for the reached vertices (test
// FaceMask.ShortestEdgePathsMatchTheReference).
std::vector<Mesh::VertexHandle> shortest_edge_path_reference(const Mesh& mesh, Mesh::VertexHandle a,
                                                             Mesh::VertexHandle b);

}  // namespace gvkit::facemap
