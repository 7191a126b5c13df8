#pragma once
// Steepest-descent paths of a piecewise-linear scalar field over a triangle mesh: from a start
// vertex down to the field's minimum on a set of target vertices, crossing triangles in straight
// lines (constant gradient per triangle), so the path is a polyline of points on edges. With a
// geodesic distance from the targets as the field, the path is the discrete geodesic.

#include <functional>
#include <vector>

#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

// A point of a path: a vertex, or a point at parameter t along a halfedge's edge (from its
// from_vertex at t = 0 to its to_vertex at t = 1).
struct SurfacePoint {
  Mesh::VertexHandle vertex;
  Mesh::HalfedgeHandle halfedge;
  double t = 0;
  bool is_vertex() const { return vertex.is_valid(); }
};

struct DescentPathOptions {
  // Edge crossings closer than this fraction of the edge to an end snap to that vertex, so
  // inserting the path creates no sliver triangles.
  double snap_fraction = 0.1;
  int max_steps = 1000000;
  Status check() const;
};

// Traces the descent of field (one value per vertex) from start until it reaches a vertex
// flagged in target (one flag per vertex), or a boundary edge between two such vertices. The
// path touches the boundary only at its end and at boundary vertices for which may_touch_boundary
// is true (none when empty). Fails when the descent stops at a local minimum other than the target,
// runs into the boundary, or does not arrive (a field that is not a distance from target).
Result<std::vector<SurfacePoint>> trace_descent_path(
    const Mesh& mesh, const std::vector<double>& field, Mesh::VertexHandle start,
    const std::vector<char>& target, const DescentPathOptions& options = {},
    const std::function<bool(Mesh::VertexHandle)>& may_touch_boundary = {});

// Position of a surface point (mm).
Mesh::Point surface_point_position(const Mesh& mesh, const SurfacePoint& point);

}  // namespace gvkit::facemap
