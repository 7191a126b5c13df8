#pragma once
// Multi-source geodesic distance on a triangle mesh by fast marching (Kimmel and Sethian 1998):
// vertices are accepted in order of distance from a heap, and each accepted vertex updates the
// far corners of its triangles from the planar wavefront through two accepted corners. The
// update unfolds the triangle into the plane and places a virtual source at distances (dA, dB)
// from the accepted edge; where the straight line from it to the corner misses that edge
// (obtuse triangles, strongly curved fronts), the update falls back to the edges (a Dijkstra
// step). Exact for a point source on a flat mesh of non-obtuse triangles; first order otherwise.
//
// No factorisation: O(n log n) per query, and a query may stop at a distance bound, so the
// grown eye and mouth regions of the face mask cost only the vertices within their margins.
// HeatGeodesics (geodesic_distance.hpp) is the reference it is compared against.

#include <limits>
#include <utility>
#include <vector>

#include "gvkit/core/mesh.hpp"

namespace gvkit::facemap {

class FastMarching {
 public:
  // Precomputes the per-vertex triangle fans of the mesh (kept by reference: the mesh must
  // outlive this object and not change).
  explicit FastMarching(const Mesh& mesh);

  // Distance (mm) from the nearest source to every vertex (by idx()); 0 at the sources.
  // Vertices farther than max_distance_mm (or on components without a source) get infinity.
  // Sources must be valid vertices of the mesh (contract).
  std::vector<double> distance(
      const std::vector<Mesh::VertexHandle>& sources,
      double max_distance_mm = std::numeric_limits<double>::infinity()) const;
  // The finite entries of distance(sources, max_distance_mm) alone, as (vertex idx(), distance)
  // in no particular order: for queries that reach few vertices, which then cost no pass over
  // all the mesh's vertices. The same values to the last bit (the same marching). Not const:
  // it keeps its per-vertex arrays between calls (reset where written), so one object must not
  // run it from two threads at once.
  std::vector<std::pair<int, double>> reached(const std::vector<Mesh::VertexHandle>& sources,
                                              double max_distance_mm);
  // The plain reference of distance(): the heap holds vertex indices and compares their d[]
  // (same acceptance order, same values; test FastMarching.HeapWithKeysMatchesTheReference).
  std::vector<double> distance_reference(
      const std::vector<Mesh::VertexHandle>& sources,
      double max_distance_mm = std::numeric_limits<double>::infinity()) const;

 private:
  // The marching of distance() on d and state (one per vertex; infinity and -1 where not yet
  // reached). On return state is -2 for the accepted vertices and a heap slot for those still
  // on the heap; `touched` (when given) gets every vertex given a distance, once.
  void march(const std::vector<Mesh::VertexHandle>& sources, double max_distance_mm, double* d,
             int* state, std::vector<int>* touched) const;

  const Mesh* mesh_;
  // For each vertex, the (other two corners) of its triangles, CSR layout.
  std::vector<int> fan_start_;
  std::vector<int> fan_;  // pairs (b, c)
  std::vector<Mesh::Point> points_;
  // reached()'s per-vertex arrays (allocated on its first call).
  std::vector<double> reached_d_;
  std::vector<int> reached_state_;
};

}  // namespace gvkit::facemap
