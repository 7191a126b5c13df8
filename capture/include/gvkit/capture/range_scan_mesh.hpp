#pragma once
// A RangeScan as a triangle mesh: one vertex per valid pixel (colour = texture), two triangles
// per 2x2 block of valid pixels whose edges are all shorter than max_edge_mm (no triangles
// across depth jumps). For PLY export and viewing.

#include "gvkit/core/mesh.hpp"
#include "gvkit/core/range_scan.hpp"

namespace gvkit::capture {

Mesh range_scan_mesh(const RangeScan& scan, double max_edge_mm = 5.0);

}  // namespace gvkit::capture
