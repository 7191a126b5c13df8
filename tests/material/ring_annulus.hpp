#pragma once
// A ring-shaped FaceAnnulus for the facemap solver tests: `rings` x `sectors` vertices, ring 0
// the inner loop (r = 1) and ring rings-1 the outer one (r = 3), triangles counter-clockwise
// seen from +z; every vertex its own source vertex.

#include <functional>

#include <Eigen/Core>

#include "gvkit/facemap/face_annulus.hpp"
#include "gvkit/facemap/tri_surface.hpp"

namespace gvkit::testing {

// Vertex (ring, sector)'s position; called ring by ring, sector by sector within a ring.
using RingPosition = std::function<Eigen::Vector3d(int ring, int sector)>;

// The planar ring: radius 1 + 2 ring / (rings - 1), angle 2 pi sector / sectors, z = 0.
Eigen::Vector3d planar_ring_position(int ring, int sector, int rings, int sectors);

// The annulus with the given positions (planar by default). The loops are told apart by the
// distance of their first vertex from the origin (inner < 2 <= outer).
facemap::FaceAnnulus ring_annulus(int rings, int sectors, const RingPosition& position = {});

}  // namespace gvkit::testing
