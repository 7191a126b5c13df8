#pragma once
// Point-to-surface distances for accuracy measurements (hole filling against the removed true
// surface, geodesic mask rims): brute force over a set of faces, meant for small patches.

#include <vector>

#include "gvkit/core/mesh.hpp"

namespace gvkit::facemap {

// Closest point to p on triangle (a, b, c) (Ericson, Real-Time Collision Detection 5.1.5).
Mesh::Point closest_point_on_triangle(const Mesh::Point& p, const Mesh::Point& a,
                                      const Mesh::Point& b, const Mesh::Point& c);

// Distance (mm) from p to the nearest of the given faces of mesh; infinity when faces is empty.
double distance_to_faces(const Mesh& mesh, const std::vector<Mesh::FaceHandle>& faces,
                         const Mesh::Point& p);

}  // namespace gvkit::facemap
