#pragma once
// PLY/OBJ mesh I/O through OpenMesh, with per-vertex colour (texture) and texture coordinates
// where the file has them. Polygons are triangulated on load. Writes are atomic.

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
  bool vertex_colors = true;  // written when the mesh has them
  bool vertex_texcoords = true;
  bool vertex_normals = false;
  // Binary PLY is written by gvkit's own serializer (OpenMesh's layout, the same bytes, several
  // times faster); true uses OpenMesh's writer (kept to check it).
  bool openmesh_writer = false;
};
Status write_mesh(const std::filesystem::path& path, const Mesh& mesh,
                  const MeshWriteOptions& options = {});

}  // namespace gvkit
