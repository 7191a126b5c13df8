#pragma once
// PLY/OBJ mesh I/O through OpenMesh, with per-vertex colour (texture) and texture coordinates
// where the file has them. Polygons are triangulated on load. Writes are atomic.

#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit {

struct MeshReadOptions {
  double scale = 1.0;  // multiply positions by this (e.g. 10 for the ICT model's centimetres)
};

// Reads a PLY or OBJ. The mesh has vertex colours when the file has them (has_vertex_colors()),
// and vertex texture coordinates when it has them (has_vertex_texcoords2D()). Fails with the file
// name when the file is missing, unreadable, or has no faces.
Result<Mesh> read_mesh(const std::filesystem::path& path, const MeshReadOptions& options = {});

struct MeshWriteOptions {
  bool binary = true;         // PLY only
  bool vertex_colors = true;  // written when the mesh has them (PLY only: OBJ has no colours)
  bool vertex_texcoords = true;
  bool vertex_normals = false;
  // Meshes are written by gvkit's own serializers, built in memory and written with one call:
  // binary PLY in OpenMesh's layout (the same bytes); ASCII PLY and OBJ with every float in its
  // shortest decimal form that reads back as the same float (OpenMesh's writer rounds to six
  // decimals), one texture coordinate and normal per vertex in OBJ ("f v/vt/vn", indices
  // equal). true uses OpenMesh's writer for every format (kept to check against).
  bool openmesh_writer = false;
};
Status write_mesh(const std::filesystem::path& path, const Mesh& mesh,
                  const MeshWriteOptions& options = {});

// A triangle mesh as flat arrays, for writers that need no Mesh (no connectivity is built).
// Pointers are borrowed; optional arrays are null when absent.
struct MeshArrays {
  size_t vertex_count = 0;
  const float* positions_mm = nullptr;  // 3 per vertex
  const float* normals = nullptr;       // 3 per vertex, or null
  const float* texcoords = nullptr;     // 2 per vertex (u, v), or null
  const float* grey = nullptr;          // 1 per vertex in [0, 1], written as r = g = b; or null
  const float* colors = nullptr;        // 3 per vertex (r, g, b in [0, 1]) when grey is null
  size_t triangle_count = 0;
  const uint32_t* indices = nullptr;  // 3 per triangle, each < vertex_count
};

// Writes `arrays` (atomically) as PLY (binary or ASCII, by options.binary) or OBJ: the same
// file as write_mesh of the Mesh made by adding the vertices and then every triangle in order,
// provided OpenMesh rejects none of them, with the same options (normals, texture coordinates
// and grey or colours written as write_mesh writes a Mesh's normals, texture coordinates and
// colours). Fails with the path for another extension, options asking for OpenMesh's writer,
// an index out of range, or a write error.
Status write_mesh_arrays(const std::filesystem::path& path, const MeshArrays& arrays,
                         const MeshWriteOptions& options = {});

}  // namespace gvkit
