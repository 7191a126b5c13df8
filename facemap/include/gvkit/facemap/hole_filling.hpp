#pragma once
// Filling of the interior holes of an open face surface (never the outer rim), after Liepa 2003
// (the method of CGAL's triangulate_refine_and_fair_hole): each hole is triangulated by the
// minimal-weight triangulation of its rim polygon (largest dihedral angle, then area; greedy ear
// clipping for rims over max_min_weight_edges), refined to the edge density of its rim (centroid
// splits while a face is larger than the local scale, circumsphere edge flips), and its new
// vertices are placed by a fairing solve with cotangent weights L and mixed Voronoi areas M: by
// default the tri-Laplacian (L M^-1)^2 L x = 0 with the rim and two rings of neighbours fixed
// (C2: positions, tangent planes and curvature match at the rim), or the seed's bi-Laplacian
// minimal surface L M^-1 L x = 0 with the rim and one ring fixed (C1, `continuity = 1`; also the
// fallback where a C2 system cannot be solved). Where the rings hold triangles without area, or
// the cotangent solve leaves the rim's hull (slivers, rims seen edge-on), the weights are kept
// positive, and the solve is redone with uniform weights when it still leaves the hull. Vertex
// colours (texture) are filled by the same solve.

#include <vector>

#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

struct HoleFillingOptions {
  // Holes with more rim edges than this are left open (0: no limit).
  int max_hole_edges = 0;
  // Spacing of the new vertices as a multiple of the rim's local edge length (smaller: denser).
  // A face is split while its centroid lies farther than density_factor * scale / sqrt(2) from
  // its corners (1: CGAL's density_control_factor sqrt(2); 0.8, about 1.5x the vertices, is
  // closer to the true surface on the holes of facemap_hole_filling_peers_bench).
  double density_factor = 0.8;
  // Rims with up to this many edges get the minimal-weight triangulation (O(n^3) time, O(n^2)
  // memory), larger ones greedy ear clipping.
  int max_min_weight_edges = 200;
  // Smoothness of the fill where it meets the rim: 1 = the seed's minimal surface, a
  // bi-Laplacian solve with the rim and one ring beyond fixed (positions and tangent planes
  // match, C1); 2 = a tri-Laplacian solve with the rim and two rings fixed (curvature matches
  // too, C2), closer to the true surface on every hole of facemap_hole_filling_peers_bench
  // (docs/benchmarks.md); a C2 fill that cannot be solved (too few rings) falls back to C1.
  int continuity = 2;
  bool fill_colors = true;  // when the mesh has vertex colours
  // A hole that shares a vertex with the outer rim is a pinch of the rim, not an interior hole.
  // true: fail; false: leave it open and count it (the clean stage crops to the face mask
  // afterwards and verifies the topology of what remains).
  bool fail_on_rim_touching_holes = true;
  Status check() const;
};

struct HoleFillingReport {
  int holes_filled = 0;
  int holes_skipped = 0;       // larger than max_hole_edges
  int holes_touching_rim = 0;  // left open (fail_on_rim_touching_holes = false)
  int holes_left_open = 0;     // named by the caller (fill_holes' `left_open`)
  int vertices_added = 0;
  int faces_added = 0;
  std::vector<int> hole_rim_edges;  // per filled hole
};

// Fills every boundary loop except the outer rim (the loop with the largest length in mm).
// Fails (failed precondition) when a hole shares a vertex with the outer rim (unless
// options.fail_on_rim_touching_holes is false: then it is left open and counted), or when a hole
// cannot be triangulated; the mesh is then left with the holes filled so far. New vertices and
// faces are appended (existing handles stay valid).
Result<HoleFillingReport> fill_holes(Mesh* mesh, const HoleFillingOptions& options = {});
// The same, leaving open (and counting) every hole whose boundary contains one of the boundary
// halfedges `left_open` (e.g. the eye and mouth openings that the face mask removes anyway).
Result<HoleFillingReport> fill_holes(Mesh* mesh, const HoleFillingOptions& options,
                                     const std::vector<Mesh::HalfedgeHandle>& left_open);

// Fills the single hole whose boundary contains the boundary halfedge `boundary_halfedge`.
Status fill_hole(Mesh* mesh, Mesh::HalfedgeHandle boundary_halfedge,
                 const HoleFillingOptions& options, HoleFillingReport* report);

}  // namespace gvkit::facemap
