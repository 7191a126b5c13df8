#include "gvkit/facemap/mesh_from_soup.hpp"

#include <cmath>

namespace gvkit::facemap {

Status SoupMeshOptions::check() const {
  if (!(min_kept_area_share >= 0.0 && min_kept_area_share <= 1.0))
    return invalid_argument("mesh repair: min kept area share must be in [0, 1], got " +
                            std::to_string(min_kept_area_share));
  return Status::ok();
}

namespace {

Status build(const TriangleSoup& soup, const std::string& name, const SoupMeshOptions& options,
             SoupMesh* out) {
  GVKIT_RETURN_IF_ERROR(options.check());
  MeshRepairOptions repair;
  repair.keep_largest_component = options.keep_largest_piece;
  repair.resolve_non_manifold_edges = true;
  repair.orient_faces = true;
  std::vector<int> original_face;
  mesh_from_triangles(soup.points, soup.colors, soup.triangles, repair, &out->mesh, &out->repair,
                      &out->original_vertex, &original_face);
  const MeshRepairReport& r = out->repair;
  if (out->mesh.n_faces() == 0)
    return failed_precondition(name + ": no face is left after the repair (" + r.summary() + ")");
  if (r.components > 1 && !options.keep_largest_piece)
    return failed_precondition(name + ": the mesh is in " + std::to_string(r.components) +
                               " pieces (one surface expected)");
  if (r.components > 1 && r.kept_area_share < options.min_kept_area_share)
    return failed_precondition(
        name + ": the largest of " + std::to_string(r.components) + " pieces holds only " +
        std::to_string(static_cast<int>(std::lround(100 * r.kept_area_share))) +
        "% of the surface (at least " +
        std::to_string(static_cast<int>(std::lround(100 * options.min_kept_area_share))) +
        "% needed): not one face surface");

  if (!soup.has_texture()) return Status::ok();
  MeshTexture& texture = out->texture;
  texture.images = soup.textures;
  texture.face_image.assign(out->mesh.n_faces(), -1);
  texture.face_uv.assign(out->mesh.n_faces(), {});
  for (auto f : out->mesh.faces()) {
    const int t = original_face[f.idx()];
    const int image = soup.triangle_texture[t];
    if (image < 0 || soup.textures[image].empty()) continue;
    // Corners by point: the repair may have flipped the face's winding.
    int k = 0;
    bool all = true;
    for (auto v : out->mesh.fv_range(f)) {
      const int point = out->original_vertex[v.idx()];
      int corner = 0;
      while (corner < 3 && soup.triangles[t][corner] != point) ++corner;
      if (corner == 3) {
        all = false;
        break;
      }
      texture.face_uv[f.idx()][k++] = soup.corner_uv[t][corner];
    }
    if (all) texture.face_image[f.idx()] = image;
  }
  if (!soup.colors.empty()) return Status::ok();
  colour_vertices_from_texture(texture, &out->mesh);
  return Status::ok();
}

}  // namespace

// Built in place: OpenMesh meshes have no move constructor.
Result<SoupMesh> mesh_from_soup(const TriangleSoup& soup, const std::string& name,
                                const SoupMeshOptions& options) {
  Result<SoupMesh> result(std::in_place);
  if (Status s = build(soup, name, options, &*result); !s.is_ok()) result = std::move(s);
  return result;
}

}  // namespace gvkit::facemap
