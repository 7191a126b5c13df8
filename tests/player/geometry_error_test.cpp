#include "gvkit/player/geometry_error.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "player_test_data.hpp"

namespace gvkit::player {
namespace {

TEST(GeometryError, KnownOffsetGivesRmsMaxAndPsnr) {
  const GeometryImage ref = testing::make_face_like_image(32, 0);
  GeometryImage img;
  img.xyz_mm = ref.xyz_mm + cv::Scalar(0, 0, 0.5);
  img.domain_mask = ref.domain_mask.clone();
  auto s = geometry_error(img, ref, 100.0);
  ASSERT_TRUE(s.is_ok());
  EXPECT_NEAR(s->rms_mm, 0.5, 1e-5);
  EXPECT_NEAR(s->max_mm, 0.5, 1e-5);
  EXPECT_NEAR(s->psnr_db, 20 * std::log10(200.0), 1e-3);
  EXPECT_EQ(s->pixels, cv::countNonZero(ref.domain_mask));
  auto own_peak = geometry_error(img, ref);
  ASSERT_TRUE(own_peak.is_ok());
  EXPECT_GT(own_peak->peak_mm, 150);  // box of a 160 mm wide patch
  EXPECT_TRUE(std::isinf(geometry_error(ref, ref)->psnr_db));

  const MeshBuffers mesh = mesh_buffers_from_geometry_image(img);
  auto e = vertex_errors_mm(mesh, ref);
  ASSERT_TRUE(e.is_ok());
  ASSERT_EQ(e->size(), mesh.vertex_count());
  for (float x : *e) EXPECT_NEAR(x, 0.5f, 1e-4f);
}

TEST(GeometryError, SizeMismatchAndDisjointDomainsFail) {
  const GeometryImage a = testing::make_face_like_image(16, 0);
  const GeometryImage b = testing::make_face_like_image(20, 0);
  EXPECT_FALSE(geometry_error(a, b).is_ok());
  EXPECT_FALSE(vertex_errors_mm(mesh_buffers_from_geometry_image(a), b).is_ok());
  GeometryImage c = a;
  c.domain_mask = cv::Mat(16, 16, CV_8U, cv::Scalar(0));
  EXPECT_FALSE(geometry_error(c, a).is_ok());
}

}  // namespace
}  // namespace gvkit::player
