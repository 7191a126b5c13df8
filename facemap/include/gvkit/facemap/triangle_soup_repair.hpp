#pragma once
// Repairs of a triangle soup that a half-edge mesh cannot hold, done before one is built
// (mesh_from_triangles calls them when MeshRepairOptions asks): faces on non-finite points,
// fins (the third and further faces of an edge) and inconsistent winding. Each works on a list of
// triangles (point indices) with a per-triangle `drop` mark, so that the caller can keep track of
// which input triangle each output face came from.

#include <array>
#include <vector>

#include "gvkit/core/mesh.hpp"

namespace gvkit::facemap {

// Marks the triangles not yet dropped that have a corner with a non-finite coordinate (NaN or
// infinite). Returns how many were marked.
int drop_non_finite_triangles(const std::vector<Mesh::Point>& points,
                              const std::vector<std::array<int, 3>>& triangles,
                              std::vector<char>* drop);

struct FinReport {
  int non_manifold_edges = 0;  // edges with more than two faces
  int dropped_faces = 0;
};

// On every edge with more than two of the triangles not dropped, keeps the two that are best
// embedded in a surface (most of their other edges shared with exactly one other triangle; ties:
// a pair that crosses the edge in opposite directions, then the lower indices) and marks the others
// (fins, flaps, internal walls). Duplicates (the same three corners) must be dropped before: they
// would count as faces of each other's edges.
FinReport drop_non_manifold_fins(const std::vector<std::array<int, 3>>& triangles,
                                 std::vector<char>* drop);

// Makes the winding of the triangles not dropped consistent across every edge they share with
// exactly one other triangle: within each piece so connected, the triangles that disagree with the
// majority winding have two corners swapped (a flipped patch turned back). A piece that cannot be
// oriented (a Moebius band) keeps the winding found first. Returns the number of triangles
// flipped; `flipped` (optional) receives a mark per triangle.
int orient_triangles(std::vector<std::array<int, 3>>* triangles, const std::vector<char>& drop,
                     std::vector<char>* flipped = nullptr);

}  // namespace gvkit::facemap
