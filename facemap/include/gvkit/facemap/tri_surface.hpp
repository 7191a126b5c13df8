#pragma once
// TriSurface: a plain indexed triangle surface (the cut annulus, the canonical domain's mesh).
// Every vertex remembers which vertices of the input mesh it interpolates, so a sample on the
// surface can be traced back to the input (ground-truth drift on meshes with known
// correspondence).

#include <array>
#include <vector>

#include <Eigen/Core>

namespace gvkit::facemap {

// One term of a vertex's position as a combination of input-mesh vertices (weights sum to 1).
struct SourceWeight {
  int vertex = -1;  // index of the input mesh vertex
  double weight = 0;
};
using SourceWeights = std::vector<SourceWeight>;

// (1 - t) * a + t * b, merging equal vertices; used when an edge is split.
SourceWeights interpolate_source_weights(const SourceWeights& a, const SourceWeights& b, double t);

struct TriSurface {
  std::vector<Eigen::Vector3d> xyz;           // per vertex (mm, or px for the canonical domain)
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from the outside/front
  std::vector<Eigen::Vector4f> colour;        // per vertex RGBA in [0, 1], or empty
  std::vector<SourceWeights> source;          // per vertex
  std::vector<int> uncut_vertex;              // per vertex: the vertex it was cut from

  int n_vertices() const { return static_cast<int>(xyz.size()); }
  int n_triangles() const { return static_cast<int>(triangles.size()); }
};

// Boundary loops of a TriSurface as ordered vertex lists (each loop follows the boundary edges
// in the direction of their triangle's winding). Non-manifold input is a contract error.
std::vector<std::vector<int>> tri_surface_boundary_loops(const TriSurface& surface);

}  // namespace gvkit::facemap
