#pragma once
// Clipping a triangle mesh along an iso-line of a per-vertex scalar: keeps {f <= level}, cutting
// triangles exactly where the linear interpolant crosses the level, so the new boundary is a
// smooth curve rather than a staircase of whole triangles. Vertices within snap_mm of the level
// are moved onto it (their f is treated as the level), which avoids sliver triangles.

#include <vector>

#include "gvkit/core/mesh.hpp"
#include "gvkit/facemap/mesh_repair.hpp"

namespace gvkit::facemap {

struct LevelSetClipOptions {
  double level = 0.0;
  // |f - level| below this (in f's units) counts as on the level. Negative: 0.1 x mean edge.
  double snap = -1.0;
  bool keep_largest_component = true;
};

// Returns the clipped mesh (colours interpolated when present). `source_vertex` (if given)
// receives for each output vertex its input vertex index, or -1 for vertices on cut edges.
// f has one value per input vertex (indexed by idx()); infinite values are fine (outside).
Mesh clip_mesh_below(const Mesh& mesh, const std::vector<double>& f,
                     const LevelSetClipOptions& options, MeshRepairReport* report = nullptr,
                     std::vector<int>* source_vertex = nullptr);
// The same into `out` (no copy of the mesh).
void clip_mesh_below(const Mesh& mesh, const std::vector<double>& f,
                     const LevelSetClipOptions& options, Mesh* out,
                     MeshRepairReport* report = nullptr, std::vector<int>* source_vertex = nullptr);

}  // namespace gvkit::facemap
