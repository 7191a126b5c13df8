#pragma once
// Triangle mesh of a geometry image: one vertex per domain pixel, two triangles per 2x2 pixel
// quad split along the shorter 3D diagonal, no triangle touching a pixel outside the domain.
// Two outputs: flat arrays for OpenGL (MeshBuffers) and the shared core Mesh for export.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/mesh.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "gvkit/core/range_scan.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::player {

struct GeometryImageMeshOptions {
  // A quad with exactly three domain pixels gives one triangle (smoother hole rims) when true;
  // only complete quads are triangulated when false.
  bool partial_quads = true;
  // Triangles with an edge longer than this (mm) are dropped; 0 keeps all. Useful for range
  // scans, whose neighbouring pixels may lie across a depth discontinuity.
  double max_edge_mm = 0.0;
  // Level of detail: use every stride-th pixel in x and y (1 = all; 2 = a quarter of the
  // vertices and triangles, for fast playback on software OpenGL). 1..16.
  int stride = 1;
  Status check() const;
};

// Flat vertex/index arrays, ready for glBufferData. Vertex i comes from pixel pixel_index[i]
// (row-major, y * width + x). Triangles are counter-clockwise seen from -z when the image rows
// run along +y and columns along +x (e.g. a camera-frame scan seen from the camera).
struct MeshBuffers {
  int width = 0, height = 0;         // size of the source image (px)
  std::vector<float> positions_mm;   // 3 per vertex
  std::vector<float> normals;        // 3 per vertex, unit length (area-weighted)
  std::vector<float> texcoords;      // 2 per vertex: ((x + 0.5) / W, (y + 0.5) / H), top-left 0
  std::vector<float> grey;           // 1 per vertex in [0, 1]; empty when the image has none
  std::vector<int32_t> pixel_index;  // 1 per vertex
  std::vector<uint32_t> indices;     // 3 per triangle

  size_t vertex_count() const { return pixel_index.size(); }
  size_t triangle_count() const { return indices.size() / 3; }
};

// Triangulates the domain pixels whose xyz is finite. image must pass image.check() (contract).
MeshBuffers mesh_buffers_from_geometry_image(const GeometryImage& image,
                                             const GeometryImageMeshOptions& options = {});

// True when OpenMesh's add_face accepts every triangle of `buffers` in order, so that
// mesh_from_buffers drops none and write_mesh_arrays(mesh_arrays(buffers)) writes the bytes
// write_mesh writes for mesh_from_buffers(buffers): no triangle repeats a vertex, no directed
// edge belongs to two triangles, and the triangles around each vertex form one fan (their edges
// opposite the vertex chain into one path or one closed cycle). False where partial quads or
// dropped triangles leave two fans touching at one pixel.
bool mesh_buffers_manifold(const MeshBuffers& buffers);
// The same check by its plain definition (each vertex's link edges compared pairwise), which
// mesh_buffers_manifold, comparing eight edges at once, must agree with (tested).
bool mesh_buffers_manifold_reference(const MeshBuffers& buffers);

// The buffers seen as core MeshArrays (borrowed pointers: valid while `buffers` lives and is
// not changed; grey null when the buffers have none).
MeshArrays mesh_arrays(const MeshBuffers& buffers);

// The core Mesh of the buffers: points (mm), vertex normals, texture coordinates, and grey
// vertex colours when the buffers have grey. Triangles OpenMesh rejects as non-manifold
// (possible where partial quads meet at one pixel) are left out and counted in *dropped_faces.
Mesh mesh_from_buffers(const MeshBuffers& buffers, int* dropped_faces = nullptr);

// A range scan seen as a geometry image: the camera pixel grid is the image, `valid` the mask
// (invalid xyz set to 0). Fails when scan.check() fails.
Result<GeometryImage> geometry_image_from_range_scan(const RangeScan& scan);

}  // namespace gvkit::player
