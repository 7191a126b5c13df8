#include <cstdlib>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "gvkit/player/geometry_error.hpp"
#include "gvkit/player/renderer.hpp"
#include "player_test_data.hpp"

namespace gvkit::player {
namespace {

constexpr int kW = 160, kH = 120;

// Pixels that differ from the background colour.
int object_pixels(const cv::Mat& bgr) {
  const cv::Vec3b bg(static_cast<uint8_t>(std::lround(kBackgroundRgb[2] * 255)),
                     static_cast<uint8_t>(std::lround(kBackgroundRgb[1] * 255)),
                     static_cast<uint8_t>(std::lround(kBackgroundRgb[0] * 255)));
  int n = 0;
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      if (std::abs(p[0] - bg[0]) + std::abs(p[1] - bg[1]) + std::abs(p[2] - bg[2]) > 6) ++n;
    }
  return n;
}

class OffscreenRender : public ::testing::Test {
 protected:
  void SetUp() override {
    RenderOptions options;
    options.width = kW;
    options.height = kH;
    auto r = Renderer::create(options);
    if (!r.is_ok()) GTEST_SKIP() << "no offscreen OpenGL here: " << r.status().message();
    renderer_ = std::move(r).value();
  }
  std::unique_ptr<Renderer> renderer_;
};

TEST_F(OffscreenRender, FaceFillsTheMiddleAndOutputIsStable) {
  const GeometryImage image = testing::make_face_like_image(64, 0);
  const MeshBuffers mesh = mesh_buffers_from_geometry_image(image);
  ViewCamera camera(scene_frame(mesh));
  renderer_->set_mesh(mesh);
  auto a = renderer_->render(camera, {});
  ASSERT_TRUE(a.is_ok()) << a.status().message();
  ASSERT_EQ(a->size(), cv::Size(kW, kH));
  ASSERT_EQ(a->type(), CV_8UC3);
  const int object = object_pixels(*a);
  EXPECT_GT(object, kW * kH / 8) << renderer_->description();
  EXPECT_LT(object, kW * kH * 9 / 10);
  // The middle pixel is surface, the corners background.
  EXPECT_EQ(object_pixels((*a)(cv::Rect(kW / 2 - 2, kH / 2 - 2, 4, 4))), 16);
  EXPECT_EQ(object_pixels((*a)(cv::Rect(0, 0, 4, 4))), 0);
  // The eye holes (at +-0.4 of the half-width, 0.3 up) show background: holes are not bridged.
  const double half_width_px = object_pixels((*a).row(kH / 2)) / 2.0;
  const int eye_x = static_cast<int>(kW / 2 + 0.4 * half_width_px);
  const int eye_y = static_cast<int>(kH / 2 - 0.3 * half_width_px);
  EXPECT_EQ(object_pixels((*a)(cv::Rect(eye_x - 1, eye_y - 1, 2, 2))), 0);
  // Same input, same pixels (also after drawing something else in between).
  renderer_->set_mesh(mesh_buffers_from_geometry_image(testing::make_face_like_image(64, 5)));
  ASSERT_TRUE(renderer_->render(camera, {}).is_ok());
  renderer_->set_mesh(mesh);
  auto b = renderer_->render(camera, {});
  ASSERT_TRUE(b.is_ok());
  EXPECT_EQ(cv::norm(*a, *b, cv::NORM_INF), 0.0);
}

TEST_F(OffscreenRender, ShadingModesGiveDifferentPictures) {
  const GeometryImage image = testing::make_face_like_image(48, 2);
  const MeshBuffers mesh = mesh_buffers_from_geometry_image(image);
  ViewCamera camera(scene_frame(mesh));
  renderer_->set_mesh(mesh);
  std::vector<cv::Mat> pictures;
  for (ShadingMode mode :
       {ShadingMode::kLit, ShadingMode::kTexture, ShadingMode::kNormals, ShadingMode::kWireframe}) {
    DrawStyle style;
    style.mode = mode;
    auto p = renderer_->render(camera, style);
    ASSERT_TRUE(p.is_ok()) << p.status().message();
    if (const char* dump = std::getenv("GVKIT_DUMP"))
      cv::imwrite(std::string(dump) + "_" + shading_mode_name(mode) + ".png", *p);
    EXPECT_GT(object_pixels(*p), kW * kH / 8) << shading_mode_name(mode);
    for (const cv::Mat& q : pictures)
      EXPECT_GT(cv::norm(*p, q, cv::NORM_L1), 1000.0) << shading_mode_name(mode);
    pictures.push_back(*p);
  }
}

TEST_F(OffscreenRender, ErrorHeatMapColoursByDistanceToTheReference) {
  const GeometryImage reference = testing::make_face_like_image(48, 0);
  GeometryImage shifted;
  shifted.xyz_mm = reference.xyz_mm.clone();
  shifted.domain_mask = reference.domain_mask.clone();
  // Left half exact, right half 2 mm off.
  for (int y = 0; y < 48; ++y)
    for (int x = 24; x < 48; ++x) shifted.xyz_mm.at<cv::Vec3f>(y, x)[2] += 2.0f;
  const MeshBuffers mesh = mesh_buffers_from_geometry_image(shifted);
  auto errors = vertex_errors_mm(mesh, reference);
  ASSERT_TRUE(errors.is_ok());
  renderer_->set_mesh(mesh);
  renderer_->set_vertex_errors(*errors);
  DrawStyle style;
  style.mode = ShadingMode::kError;
  style.error_max_mm = 2.0f;
  style.colour_bar = false;
  ViewCamera camera(scene_frame(mesh));
  auto p = renderer_->render(camera, style);
  ASSERT_TRUE(p.is_ok()) << p.status().message();
  if (const char* dump = std::getenv("GVKIT_DUMP"))
    cv::imwrite(std::string(dump) + "_error.png", *p);
  // Left of the face: Turbo at 0 (dark); right: Turbo at 1 (red).
  const cv::Scalar left = cv::mean((*p)(cv::Rect(kW / 2 - 25, kH / 2 - 5, 10, 10)));
  const cv::Scalar right = cv::mean((*p)(cv::Rect(kW / 2 + 15, kH / 2 - 5, 10, 10)));
  EXPECT_LT(left[0] + left[1] + left[2], 150) << left;
  EXPECT_GT(right[2], right[0] + 60) << right;
  EXPECT_GT(right[2], left[2] + 60) << right << left;
  style.colour_bar = true;
  auto with_bar = renderer_->render(camera, style);
  ASSERT_TRUE(with_bar.is_ok());
  EXPECT_GT(cv::norm(*with_bar, *p, cv::NORM_L1), 0.0);
}

TEST(OffscreenRenderOptions, BadSizesAreRejected) {
  RenderOptions options;
  options.width = 8;
  EXPECT_FALSE(options.check().is_ok());
  EXPECT_FALSE(Renderer::create(options).is_ok());
  options.width = 64;
  options.msaa_samples = 99;
  EXPECT_FALSE(options.check().is_ok());
}

}  // namespace
}  // namespace gvkit::player
