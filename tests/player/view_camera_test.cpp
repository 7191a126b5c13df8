#include "gvkit/player/view_camera.hpp"

#include <cmath>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "player_test_data.hpp"

namespace gvkit::player {
namespace {

Eigen::Vector4f project(const ViewCamera& camera, const Eigen::Vector3d& p) {
  Eigen::Vector4f clip = camera.clip_from_view(1.0) * camera.view_from_world() *
                         Eigen::Vector4f(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                         static_cast<float>(p.z()), 1.0f);
  return clip / clip.w();
}

TEST(ViewCamera, CameraFrameFaceIsSeenFromTheCameraSideUpright) {
  const MeshBuffers mesh = mesh_buffers_from_geometry_image(testing::make_face_like_image(40, 0));
  const SceneFrame f = scene_frame(mesh);
  EXPECT_GT(f.facing.dot(Eigen::Vector3d(0, 0, -1)), 0.9);
  EXPECT_GT(f.up.dot(Eigen::Vector3d(0, -1, 0)), 0.9);
  EXPECT_NEAR(f.right.cross(f.up).dot(f.facing), 1.0, 1e-9);
  ViewCamera camera(f);
  EXPECT_LT(camera.eye_mm().z(), f.center_mm.z());  // eye between the camera and the face
  // The centre projects to the middle, image-top (y = -80 mm, camera frame) to the top (+y NDC).
  const Eigen::Vector4f c = project(camera, f.center_mm);
  EXPECT_NEAR(c.x(), 0, 1e-4);
  EXPECT_NEAR(c.y(), 0, 1e-4);
  EXPECT_GT(c.z(), -1);
  EXPECT_LT(c.z(), 1);
  EXPECT_GT(project(camera, f.center_mm + Eigen::Vector3d(0, -60, 0)).y(), 0.2);
  EXPECT_GT(project(camera, f.center_mm + Eigen::Vector3d(60, 0, 0)).x(), 0.2);
}

TEST(ViewCamera, ModelFrameFaceFacingPlusZIsFoundToo) {
  // Mirror the face in z and y (y up, z towards the viewer, as in the ICT model): rows then run
  // down the face with the winding reversed.
  GeometryImage image = testing::make_face_like_image(40, 0);
  image.xyz_mm.forEach<cv::Vec3f>(
      [](cv::Vec3f& p, const int*) { p = cv::Vec3f(p[0], -p[1], -p[2]); });
  const SceneFrame f = scene_frame(mesh_buffers_from_geometry_image(image));
  EXPECT_GT(f.facing.dot(Eigen::Vector3d(0, 0, 1)), 0.9);
  EXPECT_GT(f.up.dot(Eigen::Vector3d(0, 1, 0)), 0.9);
}

TEST(ViewCamera, MirroredImageWithReversedWindingStillFacesTheCamera) {
  // Mirroring x reverses the triangles' winding, so the normals point away from the camera;
  // the front is still the camera side (the convex side of the bump).
  GeometryImage image = testing::make_face_like_image(40, 0);
  image.xyz_mm.forEach<cv::Vec3f>([](cv::Vec3f& p, const int*) { p[0] = -p[0]; });
  const MeshBuffers mesh = mesh_buffers_from_geometry_image(image);
  EXPECT_GT(mesh.normals[2 * 3 + 2], 0.0f);  // a vertex normal points to +z, away from the camera
  const SceneFrame f = scene_frame(mesh);
  EXPECT_GT(f.facing.dot(Eigen::Vector3d(0, 0, -1)), 0.9);
  EXPECT_GT(f.up.dot(Eigen::Vector3d(0, -1, 0)), 0.9);
}

TEST(ViewCamera, PresetsAndControls) {
  const SceneFrame f =
      scene_frame(mesh_buffers_from_geometry_image(testing::make_face_like_image(32, 0)));
  ViewCamera camera(f);
  const double d0 = (camera.eye_mm() - camera.target_mm()).norm();
  camera.set_preset(ViewPreset::kRight);
  EXPECT_GT((camera.eye_mm() - f.center_mm).dot(f.right), 0);
  camera.set_preset(ViewPreset::kLeft);
  EXPECT_LT((camera.eye_mm() - f.center_mm).dot(f.right), 0);
  camera.set_preset(ViewPreset::kOrbit, 0.25);
  EXPECT_NEAR(camera.yaw(), 60 * M_PI / 180, 1e-9);
  camera.set_preset(ViewPreset::kOrbit, 1.0);
  EXPECT_NEAR(camera.yaw(), 0, 1e-9);
  camera.zoom(0.5);
  EXPECT_NEAR((camera.eye_mm() - camera.target_mm()).norm(), d0 / 2, 1e-6);
  camera.orbit(0, 10);
  EXPECT_LE(camera.pitch(), 85 * M_PI / 180 + 1e-12);
  camera.pan(0.5, 0);
  EXPECT_NEAR((camera.target_mm() - f.center_mm).norm(), 0.25 * f.radius_mm, 1e-6);
  camera.reset();
  EXPECT_NEAR((camera.target_mm() - f.center_mm).norm(), 0, 1e-9);
  EXPECT_TRUE(parse_view_preset("orbit").is_ok());
  EXPECT_FALSE(parse_view_preset("top").is_ok());
}

}  // namespace
}  // namespace gvkit::player
