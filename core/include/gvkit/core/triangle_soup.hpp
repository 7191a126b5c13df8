#pragma once
// TriangleSoup: a PLY or OBJ mesh file as it is, before any repair. Points, triangles (polygons
// triangulated), optional per-point colours, optional per-corner texture coordinates and the
// texture images the file names. Unlike read_mesh (which goes through OpenMesh's importer and so
// drops faces with a repeated corner and detaches the third face of an edge onto new vertices),
// nothing is dropped or split here: repeated corners, duplicate faces, edges with three or more
// faces, inconsistent winding, non-finite and unreferenced points arrive as the file has them,
// for facemap's repair to count and fix (facemap/mesh_from_soup.hpp).
//
// Formats: PLY (ascii, binary little and big endian; vertex x y z, optional red green blue as
// uchar/ushort/float, optional u v / s t / texture_u texture_v; face vertex_indices or
// vertex_index, optional texcoord list of 2 per corner; `comment TextureFile NAME` names the
// texture) and OBJ (v x y z [r g b], vt, f with v, v/vt, v//vn, v/vt/vn and negative indices;
// mtllib + usemtl with map_Kd name the textures). Texture coordinates: u right, v up, [0, 1]
// over the image.

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/mesh.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit {

struct TriangleSoup {
  std::vector<Mesh::Point> points;            // file units x MeshReadOptions::scale
  std::vector<Mesh::Color> colors;            // RGBA in [0, 1], one per point, or empty
  std::vector<std::array<int, 3>> triangles;  // indices into points, all in range
  // Per triangle: its texture (index into textures, -1: none) and the (u, v) of its corners.
  // Both empty when no triangle has a texture.
  std::vector<int> triangle_texture;
  std::vector<std::array<cv::Vec2f, 3>> corner_uv;
  std::vector<std::filesystem::path> texture_paths;  // as resolved from the file
  std::vector<cv::Mat> textures;   // CV_8UC3 (BGR), one per path; read unless options say not
  int polygons = 0;                // faces in the file
  int split_polygons = 0;          // faces of more than 3 corners (each split into triangles)
  std::vector<std::string> notes;  // what was read only in part, and why (a texture missing)

  bool has_texture() const { return !triangle_texture.empty(); }
};

struct TriangleSoupReadOptions {
  double scale = 1.0;         // multiply positions by this (10 for centimetres, 1000 for metres)
  bool read_textures = true;  // load the texture images (else only their paths)
  Status check() const;
};

// Reads a .ply or .obj. Fails naming the file when it is missing, empty, malformed (with the line
// or element where), truncated, has no faces (a point cloud), or a face refers to a point the
// file does not have. A texture image that is missing or unreadable is not an error: the
// triangles that use it get no texture and a note says why.
Result<TriangleSoup> read_triangle_soup(const std::filesystem::path& path,
                                        const TriangleSoupReadOptions& options = {});

// Writes a soup as it is (no repair), so that defective meshes can be made on purpose: .ply as
// binary little endian (colours as uchar, per-corner texcoord lists, `comment TextureFile` of
// the first texture) or .obj (v with r g b when there are colours, vt per corner, and a .mtl
// beside it naming each texture path as map_Kd). Texture images are not written. Atomic.
Status write_triangle_soup(const std::filesystem::path& path, const TriangleSoup& soup);

}  // namespace gvkit
