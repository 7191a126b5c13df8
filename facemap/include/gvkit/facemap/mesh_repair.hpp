#pragma once
// Repair of triangle meshes from the world (scans, PLY/OBJ files): degenerate and duplicate faces
// are removed, faces that would make an edge non-manifold (a third face on an edge) or a vertex
// complex are dropped, unreferenced vertices are removed, and optionally only the largest
// connected component is kept. Triangle soups read as the file has them (core/triangle_soup.hpp)
// also need the repairs of triangle_soup_repair.hpp, which MeshRepairOptions switches on: faces
// on non-finite points dropped, fins resolved, winding made consistent. Every change is counted
// in the report.

#include <array>
#include <string>
#include <vector>

#include "gvkit/core/mesh.hpp"

namespace gvkit::facemap {

struct MeshRepairReport {
  int pinch_faces = 0;         // removed to open boundary pinches (mesh_from_scan)
  int non_finite_faces = 0;    // a corner at a NaN or infinite point
  int degenerate_faces = 0;    // a repeated vertex or zero area
  int duplicate_faces = 0;     // the same three vertices as an earlier face
  int non_manifold_edges = 0;  // edges with more than two faces (resolve_non_manifold_edges)
  int non_manifold_faces = 0;  // dropped: fins of those edges, or refused as non-manifold
  int flipped_faces = 0;       // winding reversed to agree with their neighbours (orient_faces)
  int components = 0;          // connected components before keeping the largest
  int removed_component_faces = 0;
  double kept_area_share = 1.0;  // the kept component's share of the surface area
  int removed_vertices = 0;      // unreferenced vertices dropped (those of removed faces too)
  bool changed() const;
  std::string summary() const;  // e.g. "3 duplicate faces, 2 components (kept the largest)"
};

struct MeshRepairOptions {
  bool keep_largest_component = true;
  // true: the half-edge structure is written directly (build_half_edges) when the kept faces
  // allow it, else OpenMesh's add_face builds it (the reference, always used when false).
  bool direct_build = true;
  // false: the caller guarantees no two triangles share their three corners (saves a sort of
  // all faces); if the direct build finds otherwise, duplicates are checked after all.
  bool check_duplicates = true;
  // Triangle soups from files (off by default: meshes built by gvkit or read through OpenMesh
  // need neither): keep two faces per edge, dropping fins (drop_non_manifold_fins), and make the
  // winding consistent (orient_triangles). Faces on non-finite points are always dropped.
  bool resolve_non_manifold_edges = false;
  bool orient_faces = false;
};

// A manifold mesh from a triangle soup: points (mm), optional per-point colours (same size or
// empty), triangles as point indices. `original_index` (if given) receives each output vertex's
// input point index, `original_face` each output face's input triangle index.
Mesh mesh_from_triangles(const std::vector<Mesh::Point>& points,
                         const std::vector<Mesh::Color>& colors,
                         const std::vector<std::array<int, 3>>& triangles,
                         const MeshRepairOptions& options, MeshRepairReport* report,
                         std::vector<int>* original_index = nullptr,
                         std::vector<int>* original_face = nullptr);

// The same, into `mesh` (OpenMesh meshes have no move constructor: this avoids a copy).
void mesh_from_triangles(const std::vector<Mesh::Point>& points,
                         const std::vector<Mesh::Color>& colors,
                         const std::vector<std::array<int, 3>>& triangles,
                         const MeshRepairOptions& options, Mesh* mesh, MeshRepairReport* report,
                         std::vector<int>* original_index = nullptr,
                         std::vector<int>* original_face = nullptr);

// Writes the half-edge structure of `mesh` (vertices 0..n_vertices-1, positions left to the
// caller) directly from triangles that are edge-manifold and consistently oriented, without
// OpenMesh's per-face checks: much faster than add_face. A vertex may have several open fans
// (a boundary loop passing it leaves each fan on its own other side). Returns false, leaving the
// mesh in an unspecified state, when the triangles are not representable: a directed edge used
// twice, a degenerate face, two faces on the same three edges, or a closed fan of faces around
// a vertex with further faces there. Every vertex needs a face.
bool build_half_edges(int n_vertices, const std::vector<std::array<int, 3>>& faces, Mesh* mesh);

// Repairs `mesh` in place (rebuilding it from its faces); colours are kept when present.
MeshRepairReport repair_mesh(Mesh* mesh, const MeshRepairOptions& options = {});

// Opens boundary pinches of a triangle list (indices into points, consistently oriented and
// edge-manifold): every vertex with several open fans keeps its fan of largest area, the other
// fans' triangles are removed, in rounds until no vertex has two open fans (at most 50). Returns
// the number of triangles removed. Pieces cut off stay in the list (mesh_from_triangles keeps the
// largest component).
int open_pinched_fans(const std::vector<Mesh::Point>& points,
                      std::vector<std::array<int, 3>>* triangles);

// Opens boundary pinches in place: a vertex with several open fans (a boundary loop touching
// itself or another loop at one vertex; OpenMesh traces such loops as separate ones and the
// Euler count misses the vertex, so a pinched mesh can pass for a genus-0 surface with the
// expected loops) keeps its fan of largest area and loses the triangles of the others
// (open_pinched_fans), then only the largest component is kept; a mesh without pinches is left
// as it is. Returns the number of triangles removed; *original (optional) receives, per vertex of
// the result, its index in the input. Colours are kept when present.
int open_boundary_pinches(Mesh* mesh, std::vector<int>* original = nullptr);

}  // namespace gvkit::facemap
