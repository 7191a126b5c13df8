#pragma once
// The geodesic face mask (the seed's face segmentation): keep the part of the face within
// geodesic radius R of the eyes and the mouth, then cut out the eye and mouth regions from their
// landmark contours, so the result is one surface of genus 0 with exactly four boundary loops
// (outer rim, two eyes, mouth) -- the input of the expression-invariant parameterization.
//
// Geodesics are expression-invariant (expressions are nearly isometric), so the mask rim covers
// the same skin in every frame. Fast marching (the default) stops its queries at the radius; the
// heat method (the reference) solves only the part of the mesh within the Euclidean ball of
// radius R around the sources (a geodesic ball lies inside the Euclidean ball of equal radius).

#include <vector>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/mesh.hpp"
#include "gvkit/core/mesh_topology.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/face_features.hpp"
#include "gvkit/facemap/fast_marching.hpp"
#include "gvkit/facemap/geodesic_distance.hpp"
#include "gvkit/facemap/nearest_vertices.hpp"

namespace gvkit::facemap {

enum class GeodesicMethod {
  kFastMarching,  // no factorisation; the margins' queries stop at their bound
  kHeat,          // the heat method (HeatGeodesics): the reference
};

struct FaceMaskOptions {
  // Geodesic radius (mm) from the eye and mouth contours. 0: radius_factor x the distance between
  // the eyes' midpoint and the mouth centre of the frame's own landmarks (about 70 mm on adults).
  double radius_mm = 0.0;
  double radius_factor = 1.0;
  MouthContour mouth_contour = MouthContour::kInner;
  // The removed regions are the contour polygons grown by these margins (mm), so a closed eye or
  // mouth (a degenerate polygon) still becomes a thin hole.
  double eye_margin_mm = 1.0;
  double mouth_margin_mm = 2.0;
  // Boundary loops of the mask besides the rim, the eyes and the mouth (gaps of the scan inside
  // the kept skin, e.g. pinches of the scan's rim that the mask moved inside) are filled.
  bool fill_stray_holes = true;
  GeodesicMethod method = GeodesicMethod::kFastMarching;
  HeatGeodesicsOptions geodesics;  // kHeat only
  Status check() const;
};

struct FaceMask {
  Mesh mesh;               // genus 0, 4 boundary loops, colours kept
  double radius_mm = 0.0;  // the radius used
  // Vertices the geodesics were solved on: the Euclidean crop (heat), the vertices within the
  // radius plus a few edges (fast marching).
  int cropped_vertices = 0;
  int stray_holes_filled = 0;  // other boundary loops inside the mask, filled
  // Triangles removed to open boundary pinches the cut left (open_boundary_pinches: a rim that
  // touches itself or a gap at one vertex, common on noisy scans' steep sides).
  int pinch_faces_removed = 0;
  // Wall time of the steps (ms): landmark check and Euclidean crop, building and factorising
  // the geodesic operators, the eye and mouth regions, the distance queries, the level-set cut,
  // the topology checks (with stray holes filled).
  struct Timing {
    double crop_ms = 0, factor_ms = 0, regions_ms = 0, distances_ms = 0, clip_ms = 0, check_ms = 0;
  } timing;
  MeshTopology topology;
  // With open holes: the indices (into open_holes) of those that their contour does not enclose
  // (the call then fails; fill them and call again).
  std::vector<int> open_holes_not_enclosed;
};

// The eye and mouth regions are the surface enclosed by the closed shortest edge path through
// their contour landmarks, grown geodesically by the margins; their boundaries and the outer rim
// are cut along iso-lines of the geodesic distances (smooth curves, not triangle staircases).
// Other boundary loops left inside the mask (gaps of the scan) are filled when
// options.fill_stray_holes. landmarks.points_mm must hold 68 points on (or within a few mm of)
// the mesh. Fails (failed precondition) with what was found when the result is not one component
// of genus 0 with 4 boundary loops, has triangles without area, or when a feature contour lies
// off the mesh.
Result<FaceMask> geodesic_face_mask(const Mesh& mesh, const FaceLandmarks& landmarks,
                                    const FaceMaskOptions& options = {});
// The same with the masked mesh written to `masked` (info->mesh is left alone): no copy of it.
Status geodesic_face_mask(const Mesh& mesh, const FaceLandmarks& landmarks,
                          const FaceMaskOptions& options, FaceMask* info, Mesh* masked);
// The same on a mesh whose eye and mouth openings were left unfilled (`open_holes`; fast
// marching only). Each open hole counts as enclosed by its feature's contour path, so the region,
// and with it every distance outside it, is that of the mesh with the hole filled whenever the
// path does not cross the fill. Fails (failed precondition) when an open hole is not enclosed by
// its contour (listed in info->open_holes_not_enclosed, found before any distance is computed)
// or would not be cut away with the region; the caller then fills those and masks again.
// Invalid argument with the heat method or a zero margin.
// Per-frame data of `mesh` that the caller has already (landmark snapping needs them too), so
// that the mask does not compute them again: the mean edge length (mm, as mean_edge_length_mm;
// < 0: computed here) and a nearest-vertex grid built on this very mesh, unchanged since (null:
// built here). Results are the same either way.
struct FaceMaskShared {
  double mean_edge_mm = -1.0;
  const NearestVertexGrid* grid = nullptr;
};
Status geodesic_face_mask(const Mesh& mesh, const FaceLandmarks& landmarks,
                          const FaceMaskOptions& options,
                          const std::vector<FeatureHole>& open_holes, FaceMask* info, Mesh* masked,
                          const FaceMaskShared& shared = {});

// The mean length of the mesh's edges (mm; 0 for a mesh without edges), summed in edge order.
double mean_edge_length_mm(const Mesh& mesh);

// The default radius for these landmarks: factor x |eyes midpoint - mouth centre| (mm).
double default_mask_radius_mm(const FaceLandmarks& landmarks, double radius_factor);

// Geodesic sources: the vertices nearest to the eye and mouth contour landmarks.
std::vector<Mesh::VertexHandle> feature_source_vertices(const Mesh& mesh,
                                                        const FaceLandmarks& landmarks,
                                                        MouthContour mouth);

}  // namespace gvkit::facemap
