#pragma once
// Steps 1-3 of the expression-invariant map (seed, Algorithm 1): the geodesic c between the two
// eyes and the geodesic d from the middle of c to the mouth, inserted into the mesh and cut open,
// which turns the 4-boundary face into an annulus: outer boundary = rim, inner boundary = eyes,
// mouth and both sides of c and d. c runs between the inner eye corners (landmarks 39 and 42
// projected onto the eye boundaries), so c ends at the same features in every frame; d ends
// where it first meets the mouth boundary (the key "d_end").

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/descent_path.hpp"
#include "gvkit/facemap/face_boundaries.hpp"
#include "gvkit/facemap/tri_surface.hpp"

namespace gvkit::facemap {

// Geodesic distance (mm) from the nearest of the source vertices to every vertex of mesh.
using DistanceFunction = std::function<Result<std::vector<double>>(
    const Mesh& mesh, const std::vector<Mesh::VertexHandle>& sources)>;

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
  std::vector<std::vector<int>> key_vertices_uncut;  // internal: per key landmark / c_mid

  std::vector<std::string> key_names() const;
  // Reverses every triangle (and so both loops), renaming the keys in the new order.
  void reverse_orientation();
};

// Builds the annulus of a face mesh. distance computes the geodesic distances the cuts follow.
// Fails like find_face_boundaries, or when a cut cannot be traced or does not leave an annulus.
Result<FaceAnnulus> make_face_annulus(const Mesh& mesh, const FaceLandmarks& landmarks,
                                      const DistanceFunction& distance,
                                      const FaceAnnulusOptions& options = {});

}  // namespace gvkit::facemap
