#pragma once
// The facemap "clean" stage for one frame: scan -> mesh (or a given mesh, repaired) -> interior
// holes filled -> geodesic face mask with the eyes and mouth cut out. The result is the input of
// the parameterization: one surface, genus 0, four boundary loops, vertex colour = texture (mm).
// Landmarks come from outside (LandmarkDetector, LandmarkTracker or a file), so frames can run
// in parallel once their landmarks are known.

#include <string>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/mesh.hpp"
#include "gvkit/core/range_scan.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/face_mask.hpp"
#include "gvkit/facemap/hole_filling.hpp"
#include "gvkit/facemap/mesh_from_scan.hpp"
#include "gvkit/facemap/mesh_repair.hpp"

namespace gvkit::facemap {

struct CleanOptions {
  MeshFromScanOptions scan;
  // Given meshes with several connected components fail (a scan that is not one face); true
  // keeps the largest instead. Scans always keep their largest component.
  bool keep_largest_mesh_component = false;
  HoleFillingOptions holes;
  FaceMaskOptions mask;
  // Scans: pixels seen through the open mouth or the eye openings (inside the inner lip or an eye
  // contour: teeth, tongue, mouth interior, eyeballs) are left out of the mesh, so the mouth and
  // eyes are holes bounded by the lips and lids whatever the expression.
  bool cut_feature_interiors = true;
  // Scans, fast marching: the openings inside the eye and mouth contours (feature_interior_holes)
  // are not filled: the mask removes them with the eye and mouth regions, which enclose them, so
  // a fill would be cut away again. The distances outside the regions are those of the filled
  // mesh except where a contour path would have cut across the fill: the eye and mouth
  // boundaries then lie the margin outside the scanned opening instead of partly on the fill.
  // An opening its contour does not enclose is filled, and a frame the mask refuses with
  // openings open is filled completely and masked again. true: fill them like every other hole
  // (the reference).
  bool fill_feature_holes = false;
  // Scans: a landmark on no pixel of the kept mesh (eye contours border the eye holes; an open
  // mouth's inner lip lies over the mouth opening) takes the nearest pixel of the kept mesh up to
  // this far; a required landmark farther away fails the frame.
  double landmark_max_gap_px = 10.0;
  // Every required landmark (nose tip, eyes, mouth) farther from the surface than half a mean
  // edge is moved to the nearest vertex (after hole filling) when that is at most this far (mm);
  // farther fails the frame. Given meshes' landmarks over an open mouth land on the lips' rim.
  double landmark_max_snap_mm = 8.0;
  Status check() const;
};

struct CleanStats {
  int input_vertices = 0, input_faces = 0;  // the scan's mesh or the given mesh after repair
  std::string repair;                       // what the repair changed
  int feature_pixels_removed = 0;           // scans: pixels inside the mouth and eye contours
  int landmarks_snapped_px = 0;  // scans: landmarks moved to the nearest pixel of the mesh
  double landmark_max_snap_px = 0.0;
  int landmarks_snapped_mm = 0;  // landmarks moved onto the surface
  double landmark_max_snap_mm = 0.0;
  int holes_filled = 0, vertices_added = 0;
  int feature_holes_open = 0;   // scans: eye and mouth openings left unfilled (the mask cuts them)
  int stray_holes_filled = 0;   // gaps inside the mask filled after masking
  int pinch_faces_removed = 0;  // triangles removed to open boundary pinches of the mask
  int output_vertices = 0, output_faces = 0;
  double radius_mm = 0.0;
  int cropped_vertices = 0;  // the part of the mesh the geodesics were solved on
  double mesh_ms = 0.0, fill_ms = 0.0, mask_ms = 0.0, total_ms = 0.0;
  FaceMask::Timing mask_timing;  // the mask's steps
};

struct CleanedFace {
  Mesh mesh;                // the 4-boundary face (mm, colours = texture)
  FaceLandmarks landmarks;  // points_px (scans only) and points_mm
  CleanStats stats;
};

// From a range scan and its landmarks' points_px (lifted to 3D here, onto the kept mesh). Errors
// name the frame.
Result<CleanedFace> clean_scan(const RangeScan& scan, FaceLandmarks landmarks,
                               const CleanOptions& options = {});

// From a mesh (mm) and its landmarks' points_mm. `name` prefixes error messages.
Result<CleanedFace> clean_mesh(Mesh mesh, const FaceLandmarks& landmarks, const std::string& name,
                               const CleanOptions& options = {});

}  // namespace gvkit::facemap
