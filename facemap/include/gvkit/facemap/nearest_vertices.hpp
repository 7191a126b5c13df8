#pragma once
// The nearest mesh vertex to each of a few query points (landmarks, contour points), exact:
// vertices are bucketed in a uniform grid and each query searches shells of cells outwards until
// no closer vertex can remain. Ties go to the lower vertex index, as in a plain scan over the
// vertices in order (nearest_vertices_reference, kept for tests and benchmarks).

#include <vector>

#include "gvkit/core/mesh.hpp"

namespace gvkit::facemap {

// Per point its nearest vertex; `distances` (if given) receives the distances (mm). An empty
// mesh gives invalid handles and infinite distances.
std::vector<Mesh::VertexHandle> nearest_vertices(const Mesh& mesh,
                                                 const std::vector<Mesh::Point>& points,
                                                 std::vector<double>* distances = nullptr);

// The same by one pass over all vertices per point (the reference).
std::vector<Mesh::VertexHandle> nearest_vertices_reference(
    const Mesh& mesh, const std::vector<Mesh::Point>& points,
    std::vector<double>* distances = nullptr);

}  // namespace gvkit::facemap
