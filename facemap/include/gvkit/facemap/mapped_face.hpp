#pragma once
// MappedFace: one frame mapped onto a parameter domain and resampled as a geometry image, with
// what the metrics need (where every pixel's sample came from, where the landmarks went, the
// map's distortion).

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvkit/core/geometry_image.hpp"
#include "gvkit/facemap/tri_surface.hpp"

namespace gvkit::facemap {

// Quality of a map from a triangle surface (mm) to the domain (px). Distortions follow the
// seed (section 4): with sigma1 >= sigma2 the singular values of each triangle's Jacobian
// (scaled so the total areas agree), eps_angle = mean of (s1/s2 + s2/s1) / 2 and eps_area =
// mean of (s1 s2 + 1/(s1 s2)) / 2, weighted by surface area; both are 1 for an isometry.
struct MapQuality {
  int triangles = 0;
  int flipped = 0;   // triangles mapped with reversed orientation or zero area
  int unmapped = 0;  // triangles or pixels the map could not place (see the producer)
  double eps_angle = 1, eps_area = 1;
};

struct MappedFace {
  GeometryImage image;
  // Per pixel (row-major), the input-mesh vertices and weights of the sampled surface point;
  // empty outside the domain mask.
  std::vector<SourceWeights> pixel_source;
  std::vector<Eigen::Vector2d> landmarks_px;  // the 68 landmarks in the domain (x right, y down)
  // EIP only: where this frame's boundary key points (eye corners, mouth corners, cut ends)
  // landed in the domain, by key name (see CanonicalDomain::key_pixels for where they belong).
  std::map<std::string, Eigen::Vector2d> keys_px;
  MapQuality quality;
  int unmapped_pixels = 0;       // domain pixels no triangle covered (filled from neighbours)
  int interior_extrema = 0;      // of the harmonic field(s)
  int boundary_nonmonotone = 0;  // inner-boundary steps where the conjugate did not increase
  int st_flipped = 0;      // triangles flipped in the flow coordinates (s, t) before resampling
  int st_untangled = 0;    // vertices moved to remove flips in (s, t) (EIP)
  std::string cut_method;  // EIP: "descent" or "edge_path" (FaceAnnulus::cut_method)
  // EIP: CPU time of the steps (ms, this thread). annulus_ms includes cut_distance_ms (the
  // geodesic distances the cuts follow); fields_ms is f, psi, s and the untangling, split in
  // the f_ms ... untangle_ms that follow it; resample_ms the geometry image; landmarks_ms the
  // landmarks' and keys' pixels; quality_ms the distortion measure.
  struct Timing {
    double annulus_ms = 0, cut_distance_ms = 0, fields_ms = 0, laplacian_ms = 0, order_ms = 0,
           f_ms = 0, psi_ms = 0, correspondence_ms = 0, untangle_ms = 0, resample_ms = 0,
           landmarks_ms = 0, quality_ms = 0, total_ms = 0;
  } timing;
  std::vector<std::string> warnings;
};

}  // namespace gvkit::facemap
