#pragma once
// Landmarks for a mesh that has none: the mesh is rendered frontally by a CPU orthographic
// z-buffer rasterizer (its texture image when it has one, else its vertex colours when they vary,
// else Lambert shading), dlib finds the 68 points in the render, and each point is lifted back
// onto the surface through the render's per-pixel triangle id (exact barycentric position of the
// sub-pixel point in that triangle).
//
// The view: first along the area-weighted mean normal of the mesh, from the side the surface
// bulges towards (the vertex centroid lies in front of the centroid of the longest boundary loop,
// the face's rim; a closed mesh keeps its normals' side). That is frontal for a face scan but
// not for a whole head (its normals nearly cancel), so the six axis directions of the model
// (+z, -z, +y, -y, +x, -x) follow, skipping those within 30 degrees of one tried. The in-plane
// roll is unknown for an arbitrary mesh, so each view is tried upright (model +y up, or +z when
// looking along y) and rotated by 180, 90 and 270 degrees; the first view and roll where dlib
// finds a face wins. When that face is small in the render (a whole head) or seen obliquely, the
// landmarks found there give the face's own frame (eyes, mouth): the mesh is rendered once more
// straight at the face, upright and framed on it, and the landmarks found in that render are
// kept (those of the first when dlib finds none there).
//
// Landmarks given in a file (landmark_points_io.hpp) find their place on a mesh with
// landmarks_on_mesh: 3-D points are taken as they are (scaled like the mesh), 2-D points are
// pixels of the mesh's texture image (mesh_texture.hpp).

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/landmark_points_io.hpp"
#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/landmark_detector.hpp"
#include "gvkit/facemap/mesh_texture.hpp"

namespace gvkit::facemap {

struct MeshRenderOptions {
  int size_px = 512;               // square image
  double fill = 0.85;              // the mesh's projected extent fills this part of the image
  cv::Vec3d light{0.3, 0.5, 1.0};  // towards the light, camera frame (x right, y up, z to viewer)
  // > 0: the image is framed on centre_mm (mesh frame) at this many mm per pixel instead of
  // fitting the whole mesh.
  double pixel_mm = 0.0;
  cv::Vec3d centre_mm{0, 0, 0};
  Status check() const;
};

// An orthographic render: camera frame x right, y up, z towards the viewer; pixel (u, v) =
// ((x - centre_x) / pixel_mm + (size - 1) / 2, -(y - centre_y) / pixel_mm + (size - 1) / 2).
struct MeshRender {
  cv::Mat image;              // CV_32F in [0, 1], background 0
  cv::Mat triangle;           // CV_32S face index per pixel, -1 where no triangle
  cv::Mat depth;              // CV_64F camera z per pixel (larger is nearer), -inf where none
  cv::Matx33d cam_from_mesh;  // rotation: camera axes (rows) in mesh coordinates
  cv::Vec3d centre_mm;        // mesh point at the image centre (mesh frame)
  double pixel_mm = 1.0;
  bool coloured = false;  // vertex colours or the texture were rendered (else shading)
  bool textured = false;  // the texture image was rendered
  cv::Vec2d pixel_of(const cv::Vec3d& p_mesh_mm) const;
};

// The frontal view direction (unit, mesh frame, pointing from the face towards the viewer), as
// described above. Fails for an empty mesh or one with no area.
Result<cv::Vec3d> frontal_view_direction(const Mesh& mesh);

// Renders the mesh seen from `view_direction` (unit, towards the viewer) with `up` (mesh frame,
// need not be orthogonal to the view; must not be parallel to it) pointing up in the image.
// `texture` (optional, one entry per face): faces with a texture image show it unshaded (a
// scan's texture carries its own light); the others their vertex colours or shading.
MeshRender render_mesh(const Mesh& mesh, const cv::Vec3d& view_direction, const cv::Vec3d& up,
                       const MeshRenderOptions& options = {}, const MeshTexture* texture = nullptr);

struct MeshLandmarkOptions {
  MeshRenderOptions render;
  // A landmark on no triangle of the render (over a hole: an eye or an open mouth) takes the
  // nearest covered pixel up to this far; farther fails.
  double max_gap_px = 12.0;
  // An eye or lip landmark (36-67) on a surface cut off by a depth jump from the surface around
  // it and deeper than this share of the face's width behind the front-most surface within
  // max_gap_px (seen through an opening into an eye socket or a whole head's mouth) moves to the
  // nearest pixel of the front surface. 0: off.
  double max_cavity_depth = 0.06;
  // When the face found spans less than min_face_span of the render (landmarks 17-67; a whole
  // head shows its face small) or the view is more than max_oblique_deg from the face's own
  // normal (eyes and mouth), the mesh is rendered again straight at the face, upright, framed so
  // that the landmarks span face_fill of the image.
  double min_face_span = 0.4;
  double max_oblique_deg = 30.0;
  double face_fill = 0.6;
  // "Straight at the face": the normal of the plane of the eyes and the mouth turned down about
  // the eye axis by this (that normal looks down on a face; the ICT model's own frontal
  // direction lies 14 degrees below it).
  double frontal_pitch_deg = 15.0;
  Status check() const;
};

struct MeshLandmarks {
  FaceLandmarks landmarks;  // points_mm on the surface (mesh frame); points_px in `render`
  MeshRender render;        // the render the landmarks were found in (upright)
  cv::Vec3d view{0, 0, 1};  // the view direction that found the face (towards the viewer)
  std::string view_name;    // "mean normal", "+z", ...
  int views_tried = 0;      // renders tried before (and including) the one that found it
  int roll_deg = 0;         // the roll of the view that found the face first
  int gap_filled = 0;       // landmarks moved to the nearest covered pixel
  int cavity_moved = 0;     // landmarks moved out of a cavity onto the front surface
};

// Renders, detects and lifts. Fails naming `name` when dlib finds no face in any view and roll,
// or when a landmark lies farther than max_gap_px from the rendered surface.
Result<MeshLandmarks> detect_mesh_landmarks(const Mesh& mesh, const LandmarkDetector& detector,
                                            const std::string& name,
                                            const MeshLandmarkOptions& options = {},
                                            const MeshTexture* texture = nullptr);

// 68 landmarks on `mesh` from a file's points (`file` names them in messages): 3-D points times
// `scale` (the mesh file's units to mm, as the mesh was scaled); 2-D points are pixels of the
// mesh's texture image (surface_points_of_texture_pixels). Fails naming the file when 2-D
// points meet a mesh without exactly one texture image, or a pixel is on no textured face.
Result<FaceLandmarks> landmarks_on_mesh(const LandmarkPoints& points, const Mesh& mesh,
                                        const MeshTexture& texture, double scale,
                                        const std::string& file);

}  // namespace gvkit::facemap
