// Surface metrics (surface_metrics.hpp): the grid normals of a sphere point outward, a tilted
// copy of a surface has the tilt as its normal error everywhere, a copy shifted along its normal
// has the shift as its Hausdorff distance, a copy shifted in its own plane has none inside but
// its outline moved, pixels outside the domain or not finite do not count, frames pool, and a
// bad window is rejected. The point-to-triangle distances: the AVX2 kernel returns the plain
// reference's doubles bit for bit, the reference agrees with an independent nearest-point
// computation, and each pixel's distance is the exact nearest of the window's triangles. The
// smoothing before the normals is its per-pixel definition to the bit.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "gvkit/codec/point_triangle_distance.hpp"
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

// The nearest point of segment ab to p, squared distance.
double segment_distance2(const cv::Vec3d& p, const cv::Vec3d& a, const cv::Vec3d& b) {
  const cv::Vec3d ab = b - a;
  const double len2 = ab.dot(ab);
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  const cv::Vec3d q = a + t * ab;
  return (p - q).dot(p - q);
}

// Independent of Ericson's regions: the foot of the perpendicular when it lies inside the
// triangle (barycentric coordinates by least squares), else the nearest of the three edges.
double nearest_point_distance2(const cv::Vec3d& p, const cv::Vec3d& a, const cv::Vec3d& b,
                               const cv::Vec3d& c) {
  double best = std::min(
      {segment_distance2(p, a, b), segment_distance2(p, b, c), segment_distance2(p, c, a)});
  const cv::Vec3d u = b - a, v = c - a, w = p - a;
  const double uu = u.dot(u), uv = u.dot(v), vv = v.dot(v), det = uu * vv - uv * uv;
  if (det > 1e-12 * uu * vv) {
    const double s = (vv * w.dot(u) - uv * w.dot(v)) / det,
                 t = (uu * w.dot(v) - uv * w.dot(u)) / det;
    if (s >= 0 && t >= 0 && s + t <= 1) {
      const cv::Vec3d q = a + s * u + t * v;
      best = std::min(best, (p - q).dot(p - q));
    }
  }
  return best;
}

TEST(PointTriangleDistance, AgreesWithTheNearestPointOfFootOrEdges) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2, 2);
  const auto point = [&] { return cv::Vec3d(u(rng), u(rng), u(rng)); };
  for (int i = 0; i < 20000; ++i) {
    const cv::Vec3d a = point(), b = point(), c = point(), p = point() * 1.5;
    const double d2 = point_triangle_distance2(p, a, b, c);
    EXPECT_NEAR(d2, nearest_point_distance2(p, a, b, c), 1e-9 * (1 + d2)) << i;
  }
}

// Random triangles over a small vertex pool, degenerate ones included (repeated corners,
// collinear corners, a corner a rounding step away), so that every region and the 0 / 0 of a
// degenerate edge occur.
TEST(PointTriangleDistance, KernelEqualsReferenceBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> x, y, z;
  for (int i = 0; i < 64; ++i) {
    cv::Vec3d v(u(rng), u(rng), u(rng));
    if (i % 8 == 1) v = cv::Vec3d(x[i - 1], y[i - 1], z[i - 1]);  // a repeated vertex
    if (i % 8 == 2)
      v = cv::Vec3d(2 * x[i - 1] - x[i - 2], 2 * y[i - 1] - y[i - 2],
                    2 * z[i - 1] - z[i - 2]);  // collinear with the two before
    if (i % 8 == 3) v = cv::Vec3d(std::nextafter(x[i - 1], 9.0), y[i - 1], z[i - 1]);
    if (i % 16 == 4) v *= 1e-12;  // tiny
    x.push_back(v[0]);
    y.push_back(v[1]);
    z.push_back(v[2]);
  }
  const VertexArrays vertices{x.data(), y.data(), z.data()};
  std::uniform_int_distribution<int32_t> pick(0, 63);
  int compared = 0;
  for (int round = 0; round < 3000; ++round) {
    const int n = round % 13;
    std::vector<int32_t> a(n), b(n), c(n);
    for (int k = 0; k < n; ++k) {
      a[k] = pick(rng);
      b[k] = round % 5 == 0 ? a[k] : pick(rng);  // a repeated corner in every fifth round
      c[k] = round % 7 == 0 ? a[k] + (a[k] < 63) : pick(rng);
    }
    // Points near the triangles, far away, and at a vertex.
    cv::Vec3d p(u(rng), u(rng), u(rng));
    if (round % 3 == 1) p *= 20.0;
    if (round % 11 == 5) p = cv::Vec3d(x[3], y[3], z[3]);
    const TriangleIndices t{a.data(), b.data(), c.data()};
    for (double bound : {std::numeric_limits<double>::infinity(), 0.25, 0.0}) {
      const double fast = nearest_triangle_distance2(p, vertices, t, n, bound);
      const double slow = nearest_triangle_distance2_reference(p, vertices, t, n, bound);
      EXPECT_EQ(std::memcmp(&fast, &slow, sizeof fast), 0)
          << "round " << round << " n " << n << ": " << fast << " vs " << slow;
      EXPECT_FALSE(std::isnan(fast));
      ++compared;
    }
  }
  EXPECT_EQ(compared, 9000);
}

// The sphere pruning kernel against its reference: every bit, for 0..32 spheres (empty ones,
// radius 0, points on a sphere's reach) and reaches from 0 up.
TEST(PointTriangleDistance, SpherePruningEqualsReference) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1, 1);
  int set_bits = 0;
  for (int round = 0; round < 2000; ++round) {
    const int n = round % 33;
    std::vector<double> x(n), y(n), z(n), r(n);
    for (int k = 0; k < n; ++k) {
      x[k] = u(rng);
      y[k] = u(rng);
      z[k] = u(rng);
      r[k] = k % 7 == 3 ? -1.0 : (k % 5 == 1 ? 0.0 : 0.9 * std::abs(u(rng)));
    }
    cv::Vec3d p(u(rng), u(rng), u(rng));
    // A point exactly at reach of sphere 0: |p - c| = r + reach.
    const double reach = round % 4 == 0 ? 0.0 : 0.5 * std::abs(u(rng));
    if (n > 0 && round % 9 == 2 && r[0] >= 0) p = cv::Vec3d(x[0] + r[0] + reach, y[0], z[0]);
    const SphereArrays spheres{x.data(), y.data(), z.data(), r.data()};
    const uint32_t fast = spheres_within_reach(p, spheres, n, reach);
    const uint32_t slow = spheres_within_reach_reference(p, spheres, n, reach);
    set_bits += std::popcount(slow);
    EXPECT_EQ(fast, slow) << "round " << round;
    if (n < 32) {
      EXPECT_EQ(slow >> n, 0u);
    }
  }
  EXPECT_GT(set_bits, 1000);
}

// A noisy surface with holes against a noisy copy: every pixel of surface_distance_mm equals the
// smallest of its distance to the reference's vertex at the same pixel and to every triangle of
// the quads within the window, found by brute force.
TEST(SurfaceMetrics, DistanceIsTheNearestTriangleOfTheWindow) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.08);
  std::uniform_real_distribution<double> u(0, 1);
  const int w = 40, h = 36;
  GeometryImage reference = image_of(w, h, 16.0, [&](int x, int y) {
    return cv::Vec3f(static_cast<float>(0.5 * x + noise(rng)),
                     static_cast<float>(0.5 * y + noise(rng)),
                     static_cast<float>(3 * std::sin(0.3 * x) * std::cos(0.2 * y) + noise(rng)));
  });
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (u(rng) < 0.06) reference.domain_mask.at<uint8_t>(y, x) = 0;  // holes
  GeometryImage decoded = reference;
  decoded.xyz_mm = reference.xyz_mm.clone();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < 3; ++k)
        decoded.xyz_mm.at<cv::Vec3f>(y, x)[k] += static_cast<float>(2 * noise(rng));
  const cv::Mat valid = surface_valid_pixels(reference, decoded);
  for (int window : {1, 3}) {
    SurfaceErrorOptions options;
    options.window_px = window;
    const cv::Mat map = surface_distance_mm(reference, decoded, options);
    const auto at = [&](int x, int y) { return cv::Vec3d(reference.xyz_mm.at<cv::Vec3f>(y, x)); };
    const auto ok = [&](int x, int y) { return valid.at<uint8_t>(y, x) != 0; };
    int checked = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (!ok(x, y)) {
          EXPECT_TRUE(std::isnan(map.at<float>(y, x)));
          continue;
        }
        const cv::Vec3d p(decoded.xyz_mm.at<cv::Vec3f>(y, x));
        double best = (p - at(x, y)).dot(p - at(x, y));
        for (int qy = std::max(0, y - window); qy <= std::min(h - 2, y + window - 1); ++qy)
          for (int qx = std::max(0, x - window); qx <= std::min(w - 2, x + window - 1); ++qx) {
            std::vector<cv::Vec3d> c;  // the quad's valid corners in the order 00, 10, 11, 01
            if (ok(qx, qy)) c.push_back(at(qx, qy));
            if (ok(qx + 1, qy)) c.push_back(at(qx + 1, qy));
            if (ok(qx + 1, qy + 1)) c.push_back(at(qx + 1, qy + 1));
            if (ok(qx, qy + 1)) c.push_back(at(qx, qy + 1));
            if (c.size() == 4) {
              best = std::min({best, point_triangle_distance2(p, c[0], c[1], c[2]),
                               point_triangle_distance2(p, c[0], c[2], c[3])});
            } else if (c.size() == 3) {
              best = std::min(best, point_triangle_distance2(p, c[0], c[1], c[2]));
            }
          }
        EXPECT_EQ(map.at<float>(y, x), static_cast<float>(std::sqrt(best))) << x << "," << y;
        ++checked;
      }
    EXPECT_GT(checked, 700);
  }
}

// smooth_positions is the per-pixel definition, summed in the same order (Gaussian weights
// from -3 sigma up, rows then columns, invalid pixels skipped), to the bit, on a noisy surface
// with holes, at several scales, including at the image border and where no valid pixel is near.
TEST(SurfaceMetrics, SmoothingIsThePerPixelWeightedMean) {
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0.0, 0.3);
  std::uniform_real_distribution<double> u(0, 1);
  const int w = 37, h = 29;
  cv::Mat xyz(h, w, CV_32FC3), valid(h, w, CV_8U);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      xyz.at<cv::Vec3f>(y, x) =
          cv::Vec3f(static_cast<float>(x + noise(rng)), static_cast<float>(-y + noise(rng)),
                    static_cast<float>(5 * std::sin(0.4 * x) + noise(rng)));
      valid.at<uint8_t>(y, x) = u(rng) < 0.85 && !(x > 25 && y > 20) ? 255 : 0;
    }
  xyz.at<cv::Vec3f>(3, 4) = cv::Vec3f(std::numeric_limits<float>::quiet_NaN(), 0, 0);
  valid.at<uint8_t>(3, 4) = 0;  // an invalid pixel's NaN must not leak
  for (double sigma : {0.5, 1.0, 2.0, 3.7}) {
    const cv::Mat out = smooth_positions(xyz, valid, sigma);
    const int radius = static_cast<int>(std::ceil(3 * sigma));
    std::vector<double> kernel(2 * radius + 1);
    for (int k = -radius; k <= radius; ++k)
      kernel[k + radius] = std::exp(-0.5 * k * k / (sigma * sigma));
    std::vector<cv::Vec4d> rows(static_cast<size_t>(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        cv::Vec4d s(0, 0, 0, 0);
        for (int k = std::max(0, x - radius); k <= std::min(w - 1, x + radius); ++k) {
          if (!valid.at<uint8_t>(y, k)) continue;
          const cv::Vec3f& p = xyz.at<cv::Vec3f>(y, k);
          const double g = kernel[k - x + radius];
          s += cv::Vec4d(g * p[0], g * p[1], g * p[2], g);
        }
        rows[static_cast<size_t>(y) * w + x] = s;
      }
    int smoothed = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        cv::Vec4d s(0, 0, 0, 0);
        for (int k = std::max(0, y - radius); k <= std::min(h - 1, y + radius); ++k)
          s += kernel[k - y + radius] * rows[static_cast<size_t>(k) * w + x];
        cv::Vec3f expected = xyz.at<cv::Vec3f>(y, x);
        if (valid.at<uint8_t>(y, x) && s[3] > 0) {
          expected = cv::Vec3f(static_cast<float>(s[0] / s[3]), static_cast<float>(s[1] / s[3]),
                               static_cast<float>(s[2] / s[3]));
          ++smoothed;
        }
        const cv::Vec3f got = out.at<cv::Vec3f>(y, x);
        EXPECT_EQ(std::memcmp(&got, &expected, sizeof got), 0)
            << "sigma " << sigma << " at " << x << "," << y << ": " << got << " vs " << expected;
      }
    EXPECT_GT(smoothed, 700);
  }
}

}  // namespace
}  // namespace gvkit::codec
