#include "gvkit/player/geometry_image_mesh.hpp"

#include <cmath>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "player_test_data.hpp"
#include "support/test_support.hpp"

namespace gvkit::player {
namespace {

// w x h image of the function xyz(x, y); every pixel in the domain unless masked later.
template <typename F>
GeometryImage make_image(int w, int h, F xyz) {
  GeometryImage image;
  image.xyz_mm.create(h, w, CV_32FC3);
  image.domain_mask = cv::Mat(h, w, CV_8U, cv::Scalar(255));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) image.xyz_mm.at<cv::Vec3f>(y, x) = xyz(x, y);
  return image;
}

GeometryImage plane(int w, int h) {
  return make_image(w, h, [](int x, int y) { return cv::Vec3f(2.0f * x, 2.0f * y, 100.0f); });
}

// Every triangle uses three domain pixels from one 2x2 quad.
void expect_triangles_inside_domain(const MeshBuffers& m, const cv::Mat& mask) {
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    int xmin = 1 << 30, xmax = -1, ymin = 1 << 30, ymax = -1;
    for (int k = 0; k < 3; ++k) {
      const int p = m.pixel_index[m.indices[3 * t + k]];
      const int x = p % m.width, y = p / m.width;
      ASSERT_NE(mask.at<uint8_t>(y, x), 0)
          << "triangle " << t << " uses masked pixel " << x << "," << y;
      xmin = std::min(xmin, x), xmax = std::max(xmax, x);
      ymin = std::min(ymin, y), ymax = std::max(ymax, y);
    }
    ASSERT_LE(xmax - xmin, 1) << "triangle " << t << " spans more than one quad";
    ASSERT_LE(ymax - ymin, 1) << "triangle " << t << " spans more than one quad";
  }
}

TEST(GeometryImageMesh, FullPlaneHasTwoTrianglesPerQuadAndNormalsTowardsCamera) {
  const MeshBuffers m = mesh_buffers_from_geometry_image(plane(8, 6));
  EXPECT_EQ(m.vertex_count(), 48u);
  EXPECT_EQ(m.triangle_count(), 2u * 7 * 5);
  ASSERT_EQ(m.normals.size(), 3 * m.vertex_count());
  for (size_t i = 0; i < m.vertex_count(); ++i) {
    EXPECT_NEAR(m.normals[3 * i + 0], 0.0, 1e-6);
    EXPECT_NEAR(m.normals[3 * i + 1], 0.0, 1e-6);
    EXPECT_NEAR(m.normals[3 * i + 2], -1.0, 1e-6);  // camera frame: towards the viewer at z = 0
  }
  // Texture coordinates of pixel (x, y) are pixel centres over the size.
  EXPECT_FLOAT_EQ(m.texcoords[0], 0.5f / 8);
  EXPECT_FLOAT_EQ(m.texcoords[1], 0.5f / 6);
  EXPECT_TRUE(m.grey.empty());
}

TEST(GeometryImageMesh, HoleRemovesItsQuadsAndNoTriangleCrossesIt) {
  GeometryImage image = plane(10, 10);
  image.domain_mask(cv::Rect(4, 4, 2, 2)).setTo(0);  // a 2x2 hole
  GeometryImageMeshOptions complete_only;
  complete_only.partial_quads = false;
  const MeshBuffers m = mesh_buffers_from_geometry_image(image, complete_only);
  EXPECT_EQ(m.vertex_count(), 96u);
  // Quads touching the hole: the 3x3 block of quads with top-left corners in x, y in 3..5.
  EXPECT_EQ(m.triangle_count(), 2u * (81 - 9));
  expect_triangles_inside_domain(m, image.domain_mask);

  // With partial quads, the 4 corner quads of that block have 3 domain pixels: one triangle each.
  const MeshBuffers p = mesh_buffers_from_geometry_image(image);
  EXPECT_EQ(p.triangle_count(), 2u * (81 - 9) + 4);
  expect_triangles_inside_domain(p, image.domain_mask);
}

TEST(GeometryImageMesh, NonFinitePixelsAreSkippedLikeMaskedOnes) {
  GeometryImage image = plane(5, 5);
  image.domain_mask.at<uint8_t>(0, 0) = 0;
  image.xyz_mm.at<cv::Vec3f>(0, 0) = cv::Vec3f(NAN, NAN, NAN);  // outside D: unspecified
  const MeshBuffers m = mesh_buffers_from_geometry_image(image);
  EXPECT_EQ(m.vertex_count(), 24u);
  EXPECT_EQ(m.triangle_count(), 2u * 16 - 1);
}

TEST(GeometryImageMesh, SplitsAlongTheShorterDiagonal) {
  // Sheared grid: the (x+1, y)-(x, y+1) diagonal is the shorter one in every quad.
  const GeometryImage image =
      make_image(4, 4, [](int x, int y) { return cv::Vec3f(x + 0.5f * y, 1.0f * y, 0.0f); });
  const MeshBuffers m = mesh_buffers_from_geometry_image(image);
  ASSERT_EQ(m.triangle_count(), 18u);
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    std::set<int> px;
    for (int k = 0; k < 3; ++k) px.insert(m.pixel_index[m.indices[3 * t + k]]);
    // No triangle holds both ends of the long diagonal: (x, y) and (x + 1, y + 1).
    for (int p : px) EXPECT_FALSE(px.count(p + 4 + 1) && (p % 4) < 3) << "triangle " << t;
  }
  // Mirrored shear: the other diagonal is shorter.
  const GeometryImage mirrored =
      make_image(4, 4, [](int x, int y) { return cv::Vec3f(x - 0.5f * y, 1.0f * y, 0.0f); });
  const MeshBuffers n = mesh_buffers_from_geometry_image(mirrored);
  for (size_t t = 0; t < n.triangle_count(); ++t) {
    std::set<int> px;
    for (int k = 0; k < 3; ++k) px.insert(n.pixel_index[n.indices[3 * t + k]]);
    for (int p : px) EXPECT_FALSE(px.count(p + 4 - 1) && (p % 4) > 0) << "triangle " << t;
  }
}

TEST(GeometryImageMesh, MaxEdgeDropsTrianglesAcrossADepthStep) {
  const GeometryImage image = make_image(6, 4, [](int x, int y) {
    return cv::Vec3f(1.0f * x, 1.0f * y, x < 3 ? 500.0f : 600.0f);  // 100 mm step
  });
  GeometryImageMeshOptions options;
  options.max_edge_mm = 10;
  const MeshBuffers m = mesh_buffers_from_geometry_image(image, options);
  EXPECT_EQ(m.triangle_count(), 2u * (2 + 2) * 3);  // the quads between x = 2 and 3 are gone
  EXPECT_EQ(mesh_buffers_from_geometry_image(image).triangle_count(), 2u * 5 * 3);
  options.max_edge_mm = -1;
  EXPECT_FALSE(options.check().is_ok());
}

TEST(GeometryImageMesh, StrideKeepsEveryNthPixel) {
  GeometryImageMeshOptions options;
  options.stride = 2;
  const MeshBuffers m = mesh_buffers_from_geometry_image(plane(9, 7), options);
  EXPECT_EQ(m.vertex_count(), 5u * 4);  // x in 0,2,4,6,8; y in 0,2,4,6
  EXPECT_EQ(m.triangle_count(), 2u * 4 * 3);
  for (int p : m.pixel_index) EXPECT_EQ((p % 9) % 2 + (p / 9) % 2, 0) << p;
  for (size_t i = 0; i < m.vertex_count(); ++i) EXPECT_NEAR(m.normals[3 * i + 2], -1.0, 1e-6);
  options.stride = 0;
  EXPECT_FALSE(options.check().is_ok());
}

TEST(GeometryImageMesh, SphereCapNormalsAreRadial) {
  const double r = 50;
  const GeometryImage image = make_image(32, 32, [&](int x, int y) {
    const double u = (x - 15.5) * 1.0, v = (y - 15.5) * 1.0;
    return cv::Vec3f(static_cast<float>(u), static_cast<float>(v),
                     static_cast<float>(200.0 - std::sqrt(r * r - u * u - v * v)));
  });
  const MeshBuffers m = mesh_buffers_from_geometry_image(image);
  const cv::Vec3d centre(0, 0, 200);
  for (size_t i = 0; i < m.vertex_count(); ++i) {
    const int x = m.pixel_index[i] % 32, y = m.pixel_index[i] / 32;
    if (x == 0 || y == 0 || x == 31 || y == 31) continue;  // one-sided at the border
    const cv::Vec3d p(m.positions_mm[3 * i], m.positions_mm[3 * i + 1], m.positions_mm[3 * i + 2]);
    const cv::Vec3d n(m.normals[3 * i], m.normals[3 * i + 1], m.normals[3 * i + 2]);
    const cv::Vec3d radial = (p - centre) / cv::norm(p - centre);
    EXPECT_GT(n.dot(radial), 0.999) << "vertex at " << x << "," << y;
  }
}

TEST(GeometryImageMesh, CoreMeshMatchesTheBuffers) {
  const GeometryImage image = testing::make_face_like_image(48, 0);
  const MeshBuffers b = mesh_buffers_from_geometry_image(image);
  int dropped = -1;
  const Mesh mesh = mesh_from_buffers(b, &dropped);
  EXPECT_EQ(mesh.n_vertices(), b.vertex_count());
  EXPECT_EQ(mesh.n_faces() + static_cast<size_t>(dropped), b.triangle_count());
  EXPECT_LE(dropped, 4);
  ASSERT_TRUE(mesh.has_vertex_colors());
  ASSERT_TRUE(mesh.has_vertex_texcoords2D());
  ASSERT_TRUE(mesh.has_vertex_normals());
  const auto v = mesh.vertex_handle(10);
  EXPECT_FLOAT_EQ(mesh.color(v)[0], b.grey[10]);
  EXPECT_FLOAT_EQ(mesh.texcoord2D(v)[1], b.texcoords[21]);
  EXPECT_DOUBLE_EQ(mesh.point(v)[2], b.positions_mm[32]);
  expect_triangles_inside_domain(b, image.domain_mask);
}

// Hand-made buffers: `n` vertices on a circle (positions only matter for the writer) and the
// given triangles.
MeshBuffers buffers_with(size_t n, const std::vector<uint32_t>& indices) {
  MeshBuffers b;
  for (size_t i = 0; i < n; ++i) {
    b.pixel_index.push_back(static_cast<int32_t>(i));
    b.positions_mm.insert(b.positions_mm.end(), {std::cos(0.5f * i), std::sin(0.5f * i), 0.1f * i});
    b.normals.insert(b.normals.end(), {0.0f, 0.0f, -1.0f});
    b.texcoords.insert(b.texcoords.end(), {0.1f * i, 0.2f});
  }
  b.indices = indices;
  return b;
}

TEST(GeometryImageMesh, ManifoldCheckFindsTwoFansAtAVertexAndRepeatedEdges) {
  EXPECT_TRUE(mesh_buffers_manifold(buffers_with(3, {0, 1, 2})));
  EXPECT_TRUE(mesh_buffers_manifold(buffers_with(4, {})));  // isolated vertices only
  // A closed fan around vertex 0 and an open one.
  EXPECT_TRUE(mesh_buffers_manifold(buffers_with(5, {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1})));
  EXPECT_TRUE(mesh_buffers_manifold(buffers_with(5, {0, 1, 2, 0, 2, 3, 0, 3, 4})));
  // Bow tie: two triangles meeting only at vertex 0.
  EXPECT_FALSE(mesh_buffers_manifold(buffers_with(5, {0, 1, 2, 0, 3, 4})));
  // A closed fan and one more triangle at its apex.
  EXPECT_FALSE(
      mesh_buffers_manifold(buffers_with(7, {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1, 0, 5, 6})));
  // The directed edge 0 -> 1 in two triangles; a repeated corner; an index out of range.
  EXPECT_FALSE(mesh_buffers_manifold(buffers_with(4, {0, 1, 2, 0, 1, 3})));
  EXPECT_FALSE(mesh_buffers_manifold(buffers_with(3, {0, 1, 1})));
  EXPECT_FALSE(mesh_buffers_manifold(buffers_with(3, {0, 1, 3})));
}

// The eight-lane check against its plain definition on random triangle sets over few vertices
// (repeated edges, bow ties, open and closed fans, degenerate triangles, valences above eight)
// and on grids with random triangles removed; both outcomes occur often.
TEST(GeometryImageMesh, ManifoldCheckEqualsItsReference) {
  std::mt19937 rng(11);
  int manifold = 0, not_manifold = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const size_t n = 3 + rng() % 12;
    std::vector<uint32_t> indices;
    if (trial % 2 == 0) {
      // A fan around vertex 0 (closed or open), then a few random triangles.
      const uint32_t rim = static_cast<uint32_t>(n - 1);
      const uint32_t count = 1 + static_cast<uint32_t>(rng() % rim);
      for (uint32_t i = 0; i < count; ++i)
        indices.insert(indices.end(), {0, 1 + i, 1 + (i + 1) % rim});
      for (uint32_t extra = static_cast<uint32_t>(rng() % 3); extra > 0; --extra)
        for (int c = 0; c < 3; ++c) indices.push_back(static_cast<uint32_t>(rng() % n));
    } else {
      for (uint32_t t = static_cast<uint32_t>(1 + rng() % 12); t > 0; --t) {
        const uint32_t a = static_cast<uint32_t>(rng() % n);
        uint32_t b = static_cast<uint32_t>(rng() % n), c = static_cast<uint32_t>(rng() % n);
        if (rng() % 16 != 0) {  // mostly non-degenerate
          while (b == a) b = static_cast<uint32_t>(rng() % n);
          while (c == a || c == b) c = static_cast<uint32_t>(rng() % n);
        }
        indices.insert(indices.end(), {a, b, c});
      }
    }
    const MeshBuffers b = buffers_with(n, indices);
    const bool expected = mesh_buffers_manifold_reference(b);
    ASSERT_EQ(mesh_buffers_manifold(b), expected) << "trial " << trial;
    (expected ? manifold : not_manifold) += 1;
  }
  for (int trial = 0; trial < 200; ++trial) {
    // A 12 x 12 grid of split quads with random triangles removed (pinches at their corners).
    const int g = 12;
    std::vector<uint32_t> indices;
    for (int y = 0; y + 1 < g; ++y)
      for (int x = 0; x + 1 < g; ++x) {
        const uint32_t a = y * g + x, b = a + 1, c = a + g, d = c + 1;
        if (rng() % 10 != 0) indices.insert(indices.end(), {a, c, d});
        if (rng() % 10 != 0) indices.insert(indices.end(), {a, d, b});
      }
    const MeshBuffers b = buffers_with(g * g, indices);
    const bool expected = mesh_buffers_manifold_reference(b);
    ASSERT_EQ(mesh_buffers_manifold(b), expected) << "grid trial " << trial;
    (expected ? manifold : not_manifold) += 1;
  }
  EXPECT_GT(manifold, 1000);
  EXPECT_GT(not_manifold, 1000);
}

// Over random domains (holes, partial quads, long edges dropped, with and without grey): where
// the check says manifold, OpenMesh takes every triangle and the PLY written from the arrays
// is byte for byte the PLY written from mesh_from_buffers; both outcomes occur.
TEST(GeometryImageMesh, ManifoldBuffersWriteThePlyOfTheOpenMeshRoute) {
  gvkit::testing::TempDir dir;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int manifold = 0, not_manifold = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int w = 6 + trial % 9, h = 5 + trial % 7;
    const double keep = 0.45 + 0.5 * unit(rng);
    GeometryImage image = make_image(w, h, [&](int x, int y) {
      return cv::Vec3f(2.0f * x, 2.0f * y, static_cast<float>(100.0 + 3.0 * unit(rng)));
    });
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (unit(rng) > keep) image.domain_mask.at<uint8_t>(y, x) = 0;
    if (trial % 2) {
      image.texture.create(h, w, CV_32F);
      cv::randu(image.texture, 0.0, 1.0);
    }
    GeometryImageMeshOptions options;
    options.partial_quads = trial % 3 != 0;
    options.max_edge_mm = trial % 5 == 0 ? 3.5 : 0.0;
    const MeshBuffers b = mesh_buffers_from_geometry_image(image, options);
    int dropped = -1;
    const Mesh mesh = mesh_from_buffers(b, &dropped);
    if (!mesh_buffers_manifold(b)) {
      ++not_manifold;
      continue;
    }
    ++manifold;
    ASSERT_EQ(dropped, 0) << "trial " << trial;
    MeshWriteOptions options_written;
    options_written.vertex_normals = trial % 4 != 1;
    ASSERT_TRUE(write_mesh(dir / "mesh.ply", mesh, options_written).is_ok());
    ASSERT_TRUE(write_mesh_arrays(dir / "arrays.ply", mesh_arrays(b), options_written).is_ok());
    const auto a = read_file(dir / "mesh.ply"), c = read_file(dir / "arrays.ply");
    ASSERT_TRUE(a.is_ok() && c.is_ok());
    ASSERT_EQ(a.value(), c.value()) << "trial " << trial;
  }
  EXPECT_GT(manifold, 50);
  EXPECT_GT(not_manifold, 20);
}

TEST(GeometryImageMesh, ArraysWriterRejectsOtherFormatsAndBadIndices) {
  gvkit::testing::TempDir dir;
  const MeshBuffers b = buffers_with(3, {0, 1, 2});
  EXPECT_EQ(write_mesh_arrays(dir / "m.stl", mesh_arrays(b)).code(), StatusCode::kUnsupported);
  MeshWriteOptions openmesh;
  openmesh.openmesh_writer = true;
  EXPECT_EQ(write_mesh_arrays(dir / "m.ply", mesh_arrays(b), openmesh).code(),
            StatusCode::kUnsupported);
  const MeshBuffers bad = buffers_with(3, {0, 1, 3});
  const Status s = write_mesh_arrays(dir / "bad.ply", mesh_arrays(bad));
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("bad.ply"), std::string::npos) << s.message();
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.ply"));
}

// Binary PLY, ASCII PLY and OBJ from the arrays read back (through OpenMesh's readers) with every
// position and texture coordinate exact, and equal the files written from the OpenMesh route.
TEST(GeometryImageMesh, ArraysWriteEveryFormatExactly) {
  gvkit::testing::TempDir dir;
  const GeometryImage image = testing::make_face_like_image(24, 3, false);
  const MeshBuffers b = mesh_buffers_from_geometry_image(image);
  ASSERT_TRUE(mesh_buffers_manifold(b));
  const Mesh mesh = mesh_from_buffers(b);
  for (const char* name : {"m.ply", "m_ascii.ply", "m.obj"}) {
    MeshWriteOptions options;
    options.binary = std::string(name) == "m.ply";
    options.vertex_normals = true;
    ASSERT_TRUE(write_mesh_arrays(dir / name, mesh_arrays(b), options).is_ok()) << name;
    ASSERT_TRUE(write_mesh(dir / (std::string("from_mesh_") + name), mesh, options).is_ok());
    const auto a = read_file(dir / name);
    const auto c = read_file(dir / (std::string("from_mesh_") + name));
    ASSERT_TRUE(a.is_ok() && c.is_ok());
    EXPECT_EQ(a.value(), c.value()) << name;
    const auto back = read_mesh(dir / name);
    ASSERT_TRUE(back.is_ok()) << back.status().message();
    ASSERT_EQ(back->n_vertices(), b.vertex_count()) << name;
    ASSERT_EQ(back->n_faces(), b.triangle_count()) << name;
    ASSERT_TRUE(back->has_vertex_texcoords2D()) << name;
    for (size_t i = 0; i < b.vertex_count(); ++i) {
      const auto v = back->vertex_handle(static_cast<int>(i));
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(static_cast<float>(back->point(v)[k]), b.positions_mm[3 * i + k]) << name;
      for (int k = 0; k < 2; ++k)
        ASSERT_EQ(static_cast<float>(back->texcoord2D(v)[k]), b.texcoords[2 * i + k]) << name;
    }
  }
}

TEST(GeometryImageMesh, RangeScanBecomesAGeometryImageWithValidAsMask) {
  RangeScan scan;
  scan.xyz_mm = cv::Mat(4, 4, CV_32FC3, cv::Scalar(1, 2, 300));
  scan.valid = cv::Mat(4, 4, CV_8U, cv::Scalar(255));
  scan.texture = cv::Mat(4, 4, CV_32F, cv::Scalar(0.5));
  scan.quality = cv::Mat(4, 4, CV_32F, cv::Scalar(1));
  scan.xyz_mm.at<cv::Vec3f>(1, 2) = cv::Vec3f(NAN, NAN, NAN);
  scan.valid.at<uint8_t>(1, 2) = 0;
  auto image = geometry_image_from_range_scan(scan);
  ASSERT_TRUE(image.is_ok()) << image.status().message();
  EXPECT_TRUE(image->check().is_ok());
  EXPECT_EQ(image->domain_mask.at<uint8_t>(1, 2), 0);
  EXPECT_EQ(mesh_buffers_from_geometry_image(*image).vertex_count(), 15u);
  scan.valid.at<uint8_t>(1, 2) = 255;  // NaN in a valid pixel
  EXPECT_FALSE(geometry_image_from_range_scan(scan).is_ok());
}

}  // namespace
}  // namespace gvkit::player
