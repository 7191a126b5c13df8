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
  // Scans: a landmark in a gap of the scan (eye contours border the eye holes) takes the
  // nearest valid pixel up to this far; a required landmark farther away fails the frame.
  double landmark_max_gap_px = 10.0;
  Status check() const;
};

struct CleanStats {
  int input_vertices = 0, input_faces = 0;  // the scan's mesh or the given mesh after repair
  std::string repair;                       // what the repair changed
  int holes_filled = 0, vertices_added = 0;
  int output_vertices = 0, output_faces = 0;
  double radius_mm = 0.0;
  double mesh_ms = 0.0, fill_ms = 0.0, mask_ms = 0.0, total_ms = 0.0;
};

struct CleanedFace {
  Mesh mesh;                // the 4-boundary face (mm, colours = texture)
  FaceLandmarks landmarks;  // points_px (scans only) and points_mm
  CleanStats stats;
};

// From a range scan and its landmarks' points_px (lifted to 3D here). Errors name the frame.
Result<CleanedFace> clean_scan(const RangeScan& scan, FaceLandmarks landmarks,
                               const CleanOptions& options = {});

// From a mesh (mm) and its landmarks' points_mm. `name` prefixes error messages.
Result<CleanedFace> clean_mesh(Mesh mesh, const FaceLandmarks& landmarks, const std::string& name,
                               const CleanOptions& options = {});

}  // namespace gvkit::facemap
