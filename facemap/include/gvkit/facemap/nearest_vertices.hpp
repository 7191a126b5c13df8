#pragma once
// The nearest mesh vertex to each of a few query points (landmarks, contour points), exact:
// vertices are bucketed in a uniform grid and each query searches shells of cells outwards until
// no closer vertex can remain. Ties go to the lower vertex index, as in a plain scan over the
// vertices in order (nearest_vertices_reference, kept for tests and benchmarks).

#include <array>
#include <vector>

#include "gvkit/core/mesh.hpp"

namespace gvkit::facemap {

// The grid over one mesh's vertices, built once and queried any number of times (landmark
// snapping and the face mask query the same mesh). Keeps a pointer to the mesh's points: the
// mesh must outlive the grid and keep its vertices unchanged. Meshes under 4096 vertices get no
// grid (each query scans the vertices). Results equal nearest_vertices().
class NearestVertexGrid {
 public:
  explicit NearestVertexGrid(const Mesh& mesh);
  // Per point its nearest vertex; `distances` (if given) receives the distances (mm).
  std::vector<Mesh::VertexHandle> nearest(const std::vector<Mesh::Point>& points,
                                          std::vector<double>* distances = nullptr) const;
  // The mesh the grid was built on.
  const Mesh& mesh() const { return *mesh_; }

 private:
  // The cell coordinate along axis k; NaN-safe: anything not inside goes to a border cell.
  int coord(double x, int k) const {
    const double t = (x - lo_[k]) / cell_;
    if (!(t >= 0)) return 0;
    return t >= dims_[k] - 1 ? dims_[k] - 1 : static_cast<int>(t);
  }
  size_t cell_of(int x, int y, int z) const {
    return (static_cast<size_t>(z) * dims_[1] + y) * dims_[0] + x;
  }

  const Mesh* mesh_;
  int n_ = 0;
  bool scan_ = true;  // no grid: queries scan the vertices
  Mesh::Point lo_;
  double cell_ = 1.0;
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<int> start_, in_cell_;
};

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
