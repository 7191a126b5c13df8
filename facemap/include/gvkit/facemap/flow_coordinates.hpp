#pragma once
// The flow coordinates (s, t) of an annulus (steps 5-8 of the seed's Algorithm 1): t = f, the
// harmonic field that is 0 on the outer and 1 on the inner boundary, and s = where the integral
// curve of grad f through the point meets the inner boundary, as a boundary parameter in [0, 1).
// The integral curves are the level sets of f's harmonic conjugate psi, so s = Phi(psi) with
// Phi the inner boundary's map from psi to the boundary parameter. The boundary parameter is
// piecewise arc length between key points with given canonical parameters (the boundary
// correspondence h), or plain arc length when none are given.

#include <map>
#include <string>
#include <vector>

#include "gvkit/core/status.hpp"
#include "gvkit/facemap/face_annulus.hpp"
#include "gvkit/facemap/harmonic_field.hpp"

namespace gvkit::facemap {

// How s is set on the rim (see flow_coordinates()).
enum class RimCorrespondence {
  kFlow,       // where the integral curves of grad f arrive (the seed's)
  kArcLength,  // the rim's arc length from its anchor
  kAngle,      // the angle around the nose tip from the anchor direction, in the frontal plane
};

// The floor of the edge weights in the Laplacian of f and psi (see cotan_laplacian()): positive,
// so no weight is negative (the maximum principle holds), and small against the weight 1 of a
// square grid's sides, so it raises only the edges that are not locally Delaunay, and those
// little. On reconstructed scans with 1 % camera noise the plain weights left some 850 interior
// extrema of f per frame and flips after untangling; the floor leaves neither. Floors of 0.001
// to 0.1 measured alike on faces; larger ones bend the integral curves of regular meshes more
// (docs/benchmarks.md, "Positive Laplacian weights").
inline constexpr double kDefaultMinCotanWeight = 0.005;

struct FlowCoordinates {
  std::vector<double> t;  // per surface vertex, in [0, 1]
  // Per triangle corner [3k + j]: s, continuous within each triangle (it may leave [0, 1) by
  // less than one period for triangles on the seam; s and s +- 1 are the same curve).
  std::vector<double> corner_s;
  std::map<std::string, double> key_u;  // boundary parameter of each key
  HarmonicFieldReport field_report;
  int boundary_nonmonotone = 0;  // inner-boundary steps where psi did not increase
  RimCorrespondence rim = RimCorrespondence::kFlow;  // what was used
  double min_cotan_weight = kDefaultMinCotanWeight;  // what was used
  int flipped = 0;  // triangles whose (s, t) image has the minority orientation or zero area
  // Free vertices moved by untangle_flow_coordinates (0 when nothing was flipped).
  int untangled_vertices = 0;
  // What f and psi were solved with (kAuto resolved on the number of vertices; under kAuto a
  // multigrid iteration that fails falls back to the factorization, not recorded here).
  HarmonicSolver solver = HarmonicSolver::kDirect;
  // CPU time of the steps (ms, this thread): the Laplacian, its elimination order, f, psi, the
  // boundary correspondence and s, the untangling.
  struct Timing {
    double laplacian_ms = 0, order_ms = 0, f_ms = 0, psi_ms = 0, correspondence_ms = 0,
           untangle_ms = 0;
  } timing;
};

// Triangles whose (s, t) image has the minority orientation or zero area.
int count_flipped(const TriSurface& surface, const std::vector<double>& t,
                  const std::vector<double>& corner_s);

// Removes flips of the discrete flow coordinates: the vertices of flipped triangles move to the
// mean of their neighbours in (s, t) (a local Tutte embedding with the region's surroundings
// fixed, solved exactly with a sparse LU), the region growing while flips remain: by two rings
// around them per round, twice as many every five rounds (a flip pushed along a strip of nearly
// degenerate triangles stays at the region's edge until the region spans the strip). fixed per
// vertex: 0 free, 1 fixed, 2 on a boundary of constant t whose s may slide (it moves to the mean
// s of its boundary neighbours; an edge joining two such vertices must be a boundary edge).
// The discrete conjugate is not exactly orthogonal to f on slivers, and the blend of s with the
// rim parameter is not linear in psi; both can flip a few triangles, which this moves by a
// fraction of a triangle. Returns the number of vertices moved.
int untangle_flow_coordinates(const TriSurface& surface, const std::vector<char>& fixed,
                              std::vector<double>* t, std::vector<double>* corner_s,
                              int max_rounds = 30);

// key_u: canonical boundary parameter of every key of annulus (from the canonical domain); the
// names must match annulus.key_names() exactly. Empty: plain arc length from keys[0].
// rim (kArcLength or kAngle, used when the annulus has a rim anchor): s is blended between the
// inner boundary's correspondence (weight t) and the rim's parameter (weight 1 - t): arc length
// from the anchor, or the angle around the nose tip from the anchor direction (monotone made),
// both as monotone maps of psi, so every level set of f still maps one to one onto a line of
// constant t: eyes, mouth and cuts land exactly where h puts them, the rim lands by arc length
// like the harmonic map's. Off: s on the rim is wherever the integral curves arrive, which
// slides by up to 17 mm along the chin when the jaw opens (the capacity of the mouth hole
// changes the flux distribution of grad f).
// min_cotan_weight: the floor of the Laplacian's edge weights (cotan_laplacian()); -infinity
// solves with the plain cotangent weights (the seed's; the reference).
// solver: how f and psi are solved (harmonic_field.hpp); kAuto decides on the annulus's number
// of vertices. The multigrid solution equals the direct one to about 1e-10
// of its largest value.
Result<FlowCoordinates> flow_coordinates(const FaceAnnulus& annulus,
                                         const std::map<std::string, double>& key_u = {},
                                         RimCorrespondence rim = RimCorrespondence::kAngle,
                                         double min_cotan_weight = kDefaultMinCotanWeight,
                                         HarmonicSolver solver = HarmonicSolver::kDirect);

}  // namespace gvkit::facemap
