#pragma once
// The expression-invariant map (seed, chapter 5, Algorithm 1) of one face frame onto the
// canonical domain D, resampled as a geometry image: cut the face into an annulus (c, d), solve
// the harmonic field f and its conjugate, map the inner boundary to D's by piecewise arc length
// between matching key points, and take for every pixel of D the surface point with the same
// flow coordinates (s, t).

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/canonical_domain.hpp"
#include "gvkit/facemap/face_annulus.hpp"
#include "gvkit/facemap/geodesic_distance.hpp"
#include "gvkit/facemap/harmonic_field.hpp"
#include "gvkit/facemap/mapped_face.hpp"

namespace gvkit::facemap {

struct EipOptions {
  FaceAnnulusOptions annulus;
  bool measure_quality = true;  // distortion and flips (forward map of every triangle)
  // How f and psi are solved (see flow_coordinates()); kAuto: multigrid on large faces.
  HarmonicSolver solver = HarmonicSolver::kAuto;
  Status check() const { return annulus.check(); }
};

// Maps mesh (a face with 4 boundary loops, mm, optional vertex colours as texture) with its 68
// landmarks onto domain. distance gives the geodesic distances the cuts follow. Fails (naming
// the reason) on a mesh or landmarks that do not fit the contract.
Result<MappedFace> map_face_eip(const Mesh& mesh, const FaceLandmarks& landmarks,
                                const CanonicalDomain& domain, const DistanceFunction& distance,
                                const EipOptions& options = {});

// The geodesic distance the cuts follow in gvkit: the heat method (HeatGeodesics), its diffusion
// time scaled by edge_scale^2 (see DistanceFunction).
DistanceFunction heat_geodesic_distance(const HeatGeodesicsOptions& options = {});

// Fills the xyz (and texture) of domain pixels that no triangle covered from their nearest
// filled neighbours; returns how many were filled.
int fill_unmapped_pixels(GeometryImage& image, const cv::Mat& filled);

// Index of the mesh vertex nearest to each landmark's points_mm.
std::vector<int> nearest_vertices(const Mesh& mesh, const FaceLandmarks& landmarks);

}  // namespace gvkit::facemap
