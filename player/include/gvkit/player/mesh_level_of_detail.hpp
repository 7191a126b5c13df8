#pragma once
// Level of detail of a geometry-image mesh for a picture of a given size: the mesh stride at
// which one grid step (the pixel spacing of the geometry image) covers about one picture pixel.
// A 320x320 geometry image drawn into a 320x320 picture puts several triangles on every pixel;
// software OpenGL pays per triangle while the picture cannot show them.

#include "gvkit/player/geometry_image_mesh.hpp"
#include "gvkit/player/view_camera.hpp"

namespace gvkit::player {

// The median length, in pixels of a width x height picture seen through `camera`, of the edges
// between horizontally and vertically neighbouring vertices of `mesh` (a stride-1 mesh of a
// geometry image: neighbours are adjacent pixels). Edges with an endpoint behind the camera are
// skipped; 0 when none is left.
double projected_grid_step_px(const MeshBuffers& mesh, const ViewCamera& camera, int width,
                              int height);

// The stride whose grid step covers about one pixel: round(1 / projected_grid_step_px), within
// 1..max_stride (1 when the step cannot be measured).
int auto_mesh_stride(const MeshBuffers& mesh, const ViewCamera& camera, int width, int height,
                     int max_stride = 4);

}  // namespace gvkit::player
