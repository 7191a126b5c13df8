// Surface metrics (surface_metrics.hpp): the grid normals of a sphere point outward, a tilted
// copy of a surface has the tilt as its normal error everywhere, a copy shifted along its normal
// has the shift as its Hausdorff distance, a copy shifted in its own plane has none inside but
// its outline moved, pixels outside the domain or not finite do not count, frames pool, and a
// bad window is rejected.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "gvkit/codec/surface_metrics.hpp"

namespace gvkit::codec {
namespace {

// A w x h geometry image of f(u, v) -> xyz over a mask that keeps a centred disc of radius r px.
template <class F>
GeometryImage image_of(int w, int h, double r, const F& f) {
  GeometryImage g;
  g.xyz_mm.create(h, w, CV_32FC3);
  g.domain_mask.create(h, w, CV_8U);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      g.xyz_mm.at<cv::Vec3f>(y, x) = f(x, y);
      const double du = x - (w - 1) / 2.0, dv = y - (h - 1) / 2.0;
      g.domain_mask.at<uint8_t>(y, x) = du * du + dv * dv <= r * r ? 255 : 0;
    }
  return g;
}

// A plane z = 0 with 0.5 mm spacing, rotated by `deg` about the x axis and shifted by t.
GeometryImage plane(double deg, cv::Vec3d t = {0, 0, 0}) {
  const double a = deg * M_PI / 180.0;
  return image_of(48, 40, 17.0, [&](int x, int y) {
    const double u = 0.5 * x, v = 0.5 * y;
    return cv::Vec3f(static_cast<float>(u + t[0]), static_cast<float>(v * std::cos(a) + t[1]),
                     static_cast<float>(v * std::sin(a) + t[2]));
  });
}

TEST(SurfaceMetrics, SphereNormalsPointOutward) {
  const double radius = 50;
  const GeometryImage g = image_of(40, 40, 18.0, [&](int x, int y) {
    const double u = (x - 19.5) * 0.02, v = (y - 19.5) * 0.02;
    return cv::Vec3f(static_cast<float>(radius * std::sin(u) * std::cos(v)),
                     static_cast<float>(radius * std::sin(v)),
                     static_cast<float>(radius * std::cos(u) * std::cos(v)));
  });
  const cv::Mat n = grid_normals(g.xyz_mm, g.domain_mask);
  int counted = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) {
      const cv::Vec3f v = n.at<cv::Vec3f>(y, x);
      if (!g.domain_mask.at<uint8_t>(y, x)) {
        EXPECT_TRUE(std::isnan(v[0]));
        continue;
      }
      const cv::Vec3d radial = cv::normalize(cv::Vec3d(g.xyz_mm.at<cv::Vec3f>(y, x)));
      // Grid rows run along +y, columns along +x: (r - p) x (d - p) faces -z, i.e. inward here.
      EXPECT_NEAR(std::abs(radial.dot(cv::Vec3d(v))), 1.0, 1e-3) << x << "," << y;
      EXPECT_NEAR(cv::norm(cv::Vec3d(v)), 1.0, 1e-5);
      ++counted;
    }
  EXPECT_GT(counted, 900);
}

TEST(SurfaceMetrics, IdenticalImagesHaveNoError) {
  const GeometryImage g = plane(10);
  const SurfaceError e = surface_error(g, g);
  EXPECT_GT(e.normal_pixels, 800);
  EXPECT_EQ(e.normal_max_deg, 0.0);
  EXPECT_EQ(e.normal_p95_deg(), 0.0);
  EXPECT_EQ(e.hausdorff_mm, 0.0);
  EXPECT_EQ(e.outline_hausdorff_mm, 0.0);
}

TEST(SurfaceMetrics, TiltIsTheNormalErrorEverywhere) {
  for (double tilt : {0.5, 2.0, 10.0}) {
    const SurfaceError e = surface_error(plane(0), plane(tilt));
    EXPECT_NEAR(e.normal_mean_deg(), tilt, 1e-3) << tilt;
    EXPECT_NEAR(e.normal_p95_deg(), tilt, SurfaceError::kBinDeg) << tilt;
    EXPECT_NEAR(e.normal_max_deg, tilt, 1e-3) << tilt;
    const cv::Mat angle = normal_error_deg(plane(0), plane(tilt));
    EXPECT_NEAR(angle.at<float>(20, 24), tilt, 1e-3);
    EXPECT_TRUE(std::isnan(angle.at<float>(0, 0)));  // outside the domain
  }
}

TEST(SurfaceMetrics, NormalShiftIsTheHausdorffDistance) {
  const SurfaceError e = surface_error(plane(0), plane(0, {0, 0, 0.3}));
  EXPECT_EQ(e.normal_max_deg, 0.0);
  EXPECT_NEAR(e.hausdorff_mm, 0.3, 1e-5);
  EXPECT_NEAR(e.to_decoded_max_mm, 0.3, 1e-5);
  EXPECT_NEAR(e.to_reference_max_mm, 0.3, 1e-5);
  EXPECT_NEAR(e.surface_mean_mm(), 0.3, 1e-5);
  EXPECT_NEAR(e.outline_hausdorff_mm, 0.3, 1e-5);
}

TEST(SurfaceMetrics, TangentialShiftMovesOnlyTheOutline) {
  // 0.7 mm along x (1.4 pixels): every interior vertex still lies on the other surface; the
  // outline moved by up to 0.7 mm, where the disc's edge runs across the shift.
  const SurfaceError e = surface_error(plane(0), plane(0, {0.7, 0, 0}));
  EXPECT_EQ(e.normal_max_deg, 0.0);
  EXPECT_NEAR(e.hausdorff_mm, 0.7, 1e-5);
  EXPECT_NEAR(e.outline_hausdorff_mm, 0.7, 1e-5);
  EXPECT_LT(e.surface_mean_mm(), 0.1);  // most vertices: 0
  // Beyond the window the distance is bounded by the nearest triangle in the window.
  SurfaceErrorOptions narrow;
  narrow.window_px = 1;
  const SurfaceError far = surface_error(plane(0), plane(0, {2.0, 0, 0}), narrow);
  EXPECT_GT(far.surface_mean_mm(), e.surface_mean_mm());
  EXPECT_LE(far.hausdorff_mm, 2.0 + 1e-5);
}

TEST(SurfaceMetrics, OnlyValidPixelsCount) {
  GeometryImage reference = plane(0), decoded = plane(5);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Outside the domain: anything, NaN included.
  reference.xyz_mm.at<cv::Vec3f>(0, 0) = cv::Vec3f(nan, nan, nan);
  decoded.xyz_mm.at<cv::Vec3f>(0, 1) = cv::Vec3f(1e6f, 1e6f, 1e6f);
  // Inside: a non-finite decoded pixel is left out (with the quadrants through it).
  decoded.xyz_mm.at<cv::Vec3f>(20, 24) = cv::Vec3f(nan, 0, 0);
  const cv::Mat valid = surface_valid_pixels(reference, decoded);
  EXPECT_EQ(valid.at<uint8_t>(20, 24), 0);
  EXPECT_EQ(valid.at<uint8_t>(20, 25), 255);
  const SurfaceError e = surface_error(reference, decoded);
  EXPECT_NEAR(e.normal_max_deg, 5.0, 1e-3);
  EXPECT_LT(e.hausdorff_mm, 20.0 * std::sin(5.0 * M_PI / 180.0));  // the far edge's lift
  EXPECT_EQ(e.normal_pixels, cv::countNonZero(valid));
}

TEST(SurfaceMetrics, FramesPool) {
  SurfaceError total;
  accumulate(total, surface_error(plane(0), plane(1)));
  accumulate(total, surface_error(plane(0), plane(3)));
  accumulate(total, surface_error(plane(0), plane(0, {0, 0, 0.2})));
  EXPECT_NEAR(total.normal_mean_deg(), (1.0 + 3.0 + 0.0) / 3.0, 1e-3);
  EXPECT_NEAR(total.normal_percentile_deg(0.5), 1.0, 0.02);
  EXPECT_NEAR(total.normal_p95_deg(), 3.0, 0.02);
  EXPECT_NEAR(total.normal_max_deg, 3.0, 1e-3);
  // The largest: the far edge of the 3-degree tilt (v up to 20 mm from the axis).
  EXPECT_GT(total.hausdorff_mm, 0.2);
  EXPECT_LT(total.hausdorff_mm, 20.0 * std::sin(3.0 * M_PI / 180.0));
  EXPECT_EQ(SurfaceError().normal_p95_deg(), 0.0);
}

TEST(SurfaceMetrics, RejectsABadWindow) {
  SurfaceErrorOptions o;
  o.window_px = 0;
  EXPECT_FALSE(o.check().is_ok());
  EXPECT_NE(o.check().message().find("window 0"), std::string::npos);
  EXPECT_THROW(surface_error(plane(0), plane(1), o), ContractError);
}

}  // namespace
}  // namespace gvkit::codec
