// The automatic mesh stride: about one grid step per picture pixel, measured on the projected
// mesh; full detail once the picture is large enough, coarser for small pictures.
#include "gvkit/player/mesh_level_of_detail.hpp"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "player_test_data.hpp"

namespace gvkit::player {
namespace {

TEST(MeshLevelOfDetail, GridStepScalesWithThePictureAndSetsTheStride) {
  const MeshBuffers mesh = mesh_buffers_from_geometry_image(testing::make_face_like_image(64, 0));
  ViewCamera camera(scene_frame(mesh));
  camera.set_preset(ViewPreset::kFront);
  const double small = projected_grid_step_px(mesh, camera, 32, 32);
  const double large = projected_grid_step_px(mesh, camera, 256, 256);
  ASSERT_GT(small, 0);
  EXPECT_NEAR(large / small, 8.0, 0.05);  // pixels per grid step grow with the picture
  // The stride is the rounded inverse of the step, within 1..max_stride.
  EXPECT_EQ(auto_mesh_stride(mesh, camera, 256, 256), 1);
  for (const int size : {8, 16, 24, 32, 64, 128})
    EXPECT_EQ(auto_mesh_stride(mesh, camera, size, size, 16),
              std::clamp<long>(std::lround(1.0 / projected_grid_step_px(mesh, camera, size, size)),
                               1, 16))
        << size;
  EXPECT_EQ(auto_mesh_stride(mesh, camera, 8, 8, 3), 3);  // capped
  // Closer is larger: zooming in halves the stride needed.
  ViewCamera close = camera;
  close.zoom(0.5);
  EXPECT_GT(projected_grid_step_px(mesh, close, 64, 64),
            projected_grid_step_px(mesh, camera, 64, 64));
}

TEST(MeshLevelOfDetail, EmptyOrUnseenMeshKeepsFullDetail) {
  const MeshBuffers empty;
  const ViewCamera camera;
  EXPECT_EQ(projected_grid_step_px(empty, camera, 64, 64), 0.0);
  EXPECT_EQ(auto_mesh_stride(empty, camera, 64, 64), 1);
}

}  // namespace
}  // namespace gvkit::player
