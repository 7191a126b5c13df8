#pragma once
// mesh_buffers_manifold() of a geometry image's mesh, once per set of vertex pixels. Without
// max_edge_mm, mesh_buffers_from_geometry_image's triangles follow from which pixels carry a
// vertex, except for the diagonal each full quad is split along, which the geometry decides; and
// the diagonal does not change the verdict: at each corner pixel a full quad's one or two
// triangles span the same wedge, from the edge to its horizontal neighbour to the edge to its
// vertical one, and add no edge shared with another quad. The frames of a geometry video share
// their domain, so `gvkit export` checks once per video instead of once per frame (about a tenth
// of a 320x320 OBJ frame's export, docs/benchmarks.md).

#include <cstdint>
#include <mutex>
#include <vector>

#include "gvkit/player/geometry_image_mesh.hpp"

namespace gvkit::player {

class ManifoldVerdictCache {
 public:
  // mesh_buffers_manifold(buffers), where buffers = mesh_buffers_from_geometry_image(image,
  // options) (the contract): the last verdict when options.max_edge_mm is 0 and buffers has the
  // size, the vertex pixels and the options of the last check, else a new check (kept).
  // Thread-safe; checks run unlocked.
  bool manifold(const MeshBuffers& buffers, const GeometryImageMeshOptions& options);
  // How many times the check ran.
  int checks() const;

 private:
  mutable std::mutex mutex_;
  bool valid_ = false;
  bool verdict_ = false;
  int width_ = 0, height_ = 0, stride_ = 0;
  bool partial_quads_ = false;
  std::vector<int32_t> pixels_;
  int checks_ = 0;
};

}  // namespace gvkit::player
