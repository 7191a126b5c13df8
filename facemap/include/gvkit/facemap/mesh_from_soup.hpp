#pragma once
// A raw mesh file's triangle soup (core/triangle_soup.hpp) -> one repaired surface: faces on
// non-finite points, degenerate and duplicate faces removed, fins of edges with more than two
// faces dropped, the winding made consistent (a flipped patch turned back), faces that would
// still make a vertex complex dropped, only the largest connected piece kept (islands, loose
// hair, a detached neck) and unreferenced points dropped (mesh_repair.hpp). Vertex colours come
// from the file, else from its texture; the texture stays available per face for renders and
// for landmarks given as texture pixels.

#include <string>
#include <vector>

#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/core/triangle_soup.hpp"
#include "gvkit/facemap/mesh_repair.hpp"
#include "gvkit/facemap/mesh_texture.hpp"

namespace gvkit::facemap {

struct SoupMeshOptions {
  // The largest piece is kept only when it holds at least this share of the surface area; less
  // means the file is not one surface with some debris (two faces, a scan in halves): refused.
  double min_kept_area_share = 0.5;
  // false: a file in several pieces is refused (the largest is not picked).
  bool keep_largest_piece = true;
  Status check() const;
};

struct SoupMesh {
  Mesh mesh;                         // positions as in the soup (its units); colours when known
  MeshTexture texture;               // empty when the file has no usable texture
  MeshRepairReport repair;           // what was changed
  std::vector<int> original_vertex;  // per vertex of mesh, its point index in the soup
};

// Fails naming `name` when nothing is left after the repair (every face degenerate, on
// non-finite points, ...), or when the file is in several pieces and the options refuse that.
Result<SoupMesh> mesh_from_soup(const TriangleSoup& soup, const std::string& name,
                                const SoupMeshOptions& options = {});

}  // namespace gvkit::facemap
