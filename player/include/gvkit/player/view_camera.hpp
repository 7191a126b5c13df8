#pragma once
// ViewCamera: an orbit camera around a geometry video (polyscope-style turntable): yaw and pitch
// about the subject's up axis, pan in the view plane, zoom by distance. The rest pose looks at the
// surface from its front, found from the mesh itself, so camera-frame scans and model-frame
// geometry images both start upright and facing the viewer. Pure math, no OpenGL.

#include <string>

#include <Eigen/Core>

#include "gvkit/core/status.hpp"
#include "gvkit/player/geometry_image_mesh.hpp"

namespace gvkit::player {

// Where a sequence sits: what to look at, how big it is, and which way its front faces.
struct SceneFrame {
  Eigen::Vector3d center_mm = Eigen::Vector3d::Zero();
  double radius_mm = 100.0;                            // bounding sphere around center
  Eigen::Vector3d facing = Eigen::Vector3d(0, 0, -1);  // unit, from the surface to the viewer
  Eigen::Vector3d up = Eigen::Vector3d(0, -1, 0);      // unit, orthogonal to facing
  Eigen::Vector3d right = Eigen::Vector3d(1, 0, 0);    // unit; right x up = facing
};

// The frame of a mesh: bounding-sphere center/radius; facing = the mean normal, flipped when the
// normals converge on that side (the viewer sees the convex side, as of a face); right =
// world +x made orthogonal to facing; up = facing x right. An empty mesh gives the defaults.
SceneFrame scene_frame(const MeshBuffers& mesh);

enum class ViewPreset { kFront, kLeft, kRight, kOrbit };
// "front", "left", "right", "orbit"; fails naming the accepted values.
Result<ViewPreset> parse_view_preset(const std::string& name);

class ViewCamera {
 public:
  ViewCamera() = default;
  explicit ViewCamera(const SceneFrame& frame) : frame_(frame) {}

  // Front view at the distance that fits the bounding sphere; clears yaw, pitch, pan, zoom.
  void reset();
  // Preset pose. kLeft/kRight orbit 50 degrees to the viewer's left/right; kOrbit sweeps yaw
  // over [-60, 60] degrees as phase goes 0 -> 1 (sinusoidal, starting and ending in front).
  void set_preset(ViewPreset preset, double phase = 0.0);

  // Mouse-style controls: angles in radians (pitch clamped to +-85 degrees), pan in units of
  // the scene radius, zoom factor > 0 (< 1 comes closer).
  void orbit(double d_yaw, double d_pitch);
  void pan(double dx, double dy);
  void zoom(double factor);

  Eigen::Vector3d eye_mm() const;
  Eigen::Vector3d target_mm() const;
  // 4x4 column-major OpenGL matrices: view_from_world (right-handed, looking down -z) and
  // clip_from_view for the given width / height aspect.
  Eigen::Matrix4f view_from_world() const;
  Eigen::Matrix4f clip_from_view(double aspect) const;

  double yaw() const { return yaw_; }
  double pitch() const { return pitch_; }
  const SceneFrame& frame() const { return frame_; }
  double fov_y_deg = 30.0;

 private:
  Eigen::Vector3d direction() const;  // unit, from the target to the eye
  Eigen::Vector3d pan_offset_mm() const;

  SceneFrame frame_;
  double yaw_ = 0, pitch_ = 0, zoom_ = 1;
  Eigen::Vector2d pan_ = Eigen::Vector2d::Zero();
};

}  // namespace gvkit::player
