#pragma once
// Landmarks for a mesh that has none: the mesh is rendered frontally by a CPU orthographic
// z-buffer rasterizer (its vertex colours when they vary, else Lambert shading), dlib finds the 68
// points in the render, and each point is lifted back onto the surface through the render's
// per-pixel triangle id (exact barycentric position of the sub-pixel point in that triangle).
//
// The view: along the area-weighted mean normal of the mesh, from the side the surface bulges
// towards (the vertex centroid lies in front of the centroid of the longest boundary loop, the
// face's rim; a closed mesh keeps its normals' side). The in-plane roll is unknown for an
// arbitrary mesh, so the render is tried upright (model +y up) and rotated by 90, 180 and 270
// degrees; the first roll where dlib finds a face wins.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/landmark_detector.hpp"

namespace gvkit::facemap {

struct MeshRenderOptions {
  int size_px = 512;               // square image
  double fill = 0.85;              // the mesh's projected extent fills this part of the image
  cv::Vec3d light{0.3, 0.5, 1.0};  // towards the light, camera frame (x right, y up, z to viewer)
  Status check() const;
};

// An orthographic render: camera frame x right, y up, z towards the viewer; pixel (u, v) =
// ((x - centre_x) / pixel_mm + (size - 1) / 2, -(y - centre_y) / pixel_mm + (size - 1) / 2).
struct MeshRender {
  cv::Mat image;              // CV_32F in [0, 1], background 0
  cv::Mat triangle;           // CV_32S face index per pixel, -1 where no triangle
  cv::Matx33d cam_from_mesh;  // rotation: camera axes (rows) in mesh coordinates
  cv::Vec3d centre_mm;        // mesh point at the image centre (mesh frame)
  double pixel_mm = 1.0;
  bool coloured = false;  // vertex colours were rendered (else shading)
  cv::Vec2d pixel_of(const cv::Vec3d& p_mesh_mm) const;
};

// The frontal view direction (unit, mesh frame, pointing from the face towards the viewer), as
// described above. Fails for an empty mesh or one with no area.
Result<cv::Vec3d> frontal_view_direction(const Mesh& mesh);

// Renders the mesh seen from `view_direction` (unit, towards the viewer) with `up` (mesh frame,
// need not be orthogonal to the view; must not be parallel to it) pointing up in the image.
MeshRender render_mesh(const Mesh& mesh, const cv::Vec3d& view_direction, const cv::Vec3d& up,
                       const MeshRenderOptions& options = {});

struct MeshLandmarkOptions {
  MeshRenderOptions render;
  // A landmark on no triangle of the render (over a hole: an eye or an open mouth) takes the
  // nearest covered pixel up to this far; farther fails.
  double max_gap_px = 12.0;
  Status check() const;
};

struct MeshLandmarks {
  FaceLandmarks landmarks;  // points_mm on the surface (mesh frame); points_px in `render`
  MeshRender render;        // the render the landmarks were found in (rolled upright)
  int roll_deg = 0;         // the roll that found the face
  int gap_filled = 0;       // landmarks moved to the nearest covered pixel
};

// Renders, detects and lifts. Fails naming `name` when dlib finds no face in any roll of the
// render, or when a landmark lies farther than max_gap_px from the rendered surface.
Result<MeshLandmarks> detect_mesh_landmarks(const Mesh& mesh, const LandmarkDetector& detector,
                                            const std::string& name,
                                            const MeshLandmarkOptions& options = {});

}  // namespace gvkit::facemap
