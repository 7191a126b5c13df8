#pragma once
// Steps 1-3 of the expression-invariant map (seed, Algorithm 1): the geodesic c between the two
// eyes and the geodesic d from the middle of c to the mouth, inserted into the mesh and cut open,
// which turns the 4-boundary face into an annulus: outer boundary = rim, inner boundary = eyes,
// mouth and both sides of c and d. c runs between the inner eye corners (landmarks 39 and 42
// projected onto the eye boundaries) over the top of the nose bridge (landmark 27, c's middle),
// so c ends and bends at the same features in every frame; d runs
// from the middle of c over the nose tip (landmark 30, the key "30") down to the middle of the
// upper lip (landmark 62 projected onto the mouth boundary; d ends where it first meets the
// mouth boundary, the key "d_end"), so d follows the nose line in every frame instead of
// passing the nose on whichever side is shorter in this frame.

#include <array>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/descent_path.hpp"
#include "gvkit/facemap/face_boundaries.hpp"
#include "gvkit/facemap/tri_surface.hpp"

namespace gvkit::facemap {

// Geodesic distance (mm) from each source vertex to every vertex of mesh: one field per source
// (indexed by vertex idx()), so one factorization can serve all of them. mesh may be a part cut
// out of a larger surface around the sources; edge_scale is then the larger surface's mean edge
// length over mesh's own (1 for a whole surface), so a method whose parameters follow the mean
// edge length (the heat method's diffusion time) gives the larger surface's field.
using DistanceFunction = std::function<Result<std::vector<std::vector<double>>>(
    const Mesh& mesh, const std::vector<Mesh::VertexHandle>& sources, double edge_scale)>;

struct FaceAnnulusOptions {
  FaceBoundaryOptions boundaries;
  DescentPathOptions path;
  // A landmark projected onto its boundary closer than this fraction of an edge to a vertex uses
  // that vertex; otherwise the boundary edge is split there. 0.5 always snaps.
  double key_snap_fraction = 0.1;
  // Let c start by running along the eye boundary (its start then moves to where it leaves
  // the boundary). Needed on the pixel-grid domain, whose jagged holes can leave a key vertex
  // no other way out; off for faces, so c starts exactly at the landmark.
  bool slide_along_start = false;
  // Trace the cuts as descent paths (else directly as shortest edge paths), and fall back to
  // shortest edge paths when the descent paths do not give an annulus.
  bool descent_paths = true;
  // c runs 42 -> 27 -> 39, through the top of the nose bridge, whose vertex is c's middle (the
  // key c_mid); off: one geodesic 42 -> 39 and its middle by arc length (the seed's wording),
  // whose route and middle move between frames where the nose bridge is a flat saddle.
  bool c_through_nose_bridge = true;
  bool edge_path_fallback = true;
  // The distance fields of the descent cuts are solved only on the part of the mesh within this
  // distance (mm, along edges) of the shortest edge paths the cuts roughly follow (a descent
  // that fails there is traced again with the whole mesh's fields); 0: on the whole mesh.
  double distance_crop_mm = 20.0;
  Status check() const;
};

// A named key point on the inner boundary: "<landmark>#<k>", "c_mid#<k>" or "d_end#<k>", k
// numbering the copies a cut made of the same point, in boundary order from the anchor "36#0".
struct BoundaryKey {
  std::string name;
  int position = 0;  // index into FaceAnnulus::inner_loop
};

struct FaceAnnulus {
  TriSurface surface;
  std::vector<int> outer_loop;    // surface vertices, boundary order
  std::vector<int> inner_loop;    // surface vertices, boundary order, starting at the anchor key
  std::vector<BoundaryKey> keys;  // in inner-loop order; keys[0] is "36#0" at position 0
  // The rim's anchor: the point at rim_anchor_t along the outer-loop edge rim_anchor[0] ->
  // rim_anchor[1] (surface vertices) where the line from the nose tip (30) through the chin (8)
  // leaves the face in the frontal (x, y) plane; the origin of the rim's arc length.
  std::array<int, 2> rim_anchor = {-1, -1};
  double rim_anchor_t = 0;
  Eigen::Vector2d rim_centre = Eigen::Vector2d::Zero();      // nose tip (30) in the frontal plane
  Eigen::Vector2d rim_direction = Eigen::Vector2d::UnitY();  // unit, toward the chin (8)
  // How the cuts were traced: "descent" (straight lines across triangles down the geodesic
  // distance) or "edge_path" (shortest edge paths with the boundaries and earlier cuts as
  // barriers: the fallback when a descent path touches a boundary, crosses itself or the other
  // cut, or does not leave an annulus).
  std::string cut_method = "descent";
  // Faces removed around boundary pinches (a vertex where a hole touches the rim or another
  // hole) before cutting; surface.source still names the input mesh's vertices.
  int pinch_faces_removed = 0;
  double distance_ms = 0;  // CPU time (ms, this thread) spent in the distance function
  std::vector<std::pair<std::string, int>> key_vertices_uncut;  // internal: (base name, vertex)

  std::vector<std::string> key_names() const;
  // Reverses every triangle (and so both loops), renaming the keys in the new order.
  void reverse_orientation();
};

// Builds the annulus of a face mesh. distance computes the geodesic distances the cuts follow.
// The cuts are traced as descent paths first; when those do not give a valid annulus they are
// traced again as shortest edge paths (FaceAnnulus::cut_method). Fails like
// find_face_boundaries, or when neither way gives an annulus (both reasons in the message).
Result<FaceAnnulus> make_face_annulus(const Mesh& mesh, const FaceLandmarks& landmarks,
                                      const DistanceFunction& distance,
                                      const FaceAnnulusOptions& options = {});

}  // namespace gvkit::facemap
