// Mesh files read as they are: PLY (ascii, binary both endians) and OBJ (polygons, negative
// indices, materials with textures); defects that OpenMesh's importer drops arrive intact; bad
// files fail naming the file and where.
#include "gvkit/core/triangle_soup.hpp"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::contains;
using testing::TempDir;

void write_text(const std::filesystem::path& path, const std::string& text) {
  ASSERT_TRUE(write_file_atomically(path, text).is_ok());
}

TEST(TriangleSoup, ObjPolygonsNegativeIndicesAndATexture) {
  TempDir dir;
  cv::Mat texture(8, 16, CV_8UC3, cv::Scalar(10, 20, 200));  // BGR: red
  ASSERT_TRUE(write_image(dir / "skin.png", texture).is_ok());
  write_text(dir / "head.mtl", "newmtl skin\nKd 1 1 1\nmap_Kd -s 1 1 1 skin.png\nnewmtl plain\n");
  write_text(dir / "head.obj",
             "# a quad, a pentagon and a triangle\nmtllib head.mtl\n"
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nv 3 0.5 0\n"
             "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
             "usemtl skin\nf 1/1/1 2/2/1 3/3/1 4/4/1\n"
             "usemtl plain\nf 2 5 6 3 -1\n"
             "f -5//1 -3//1 -2//1\n");
  auto soup = read_triangle_soup(dir / "head.obj", {.scale = 10.0});
  ASSERT_TRUE(soup.is_ok()) << soup.status().message();
  EXPECT_EQ(soup->points.size(), 7u);
  EXPECT_EQ(soup->points[6], Mesh::Point(30, 5, 0));  // scaled
  EXPECT_EQ(soup->polygons, 3);
  EXPECT_EQ(soup->split_polygons, 2);
  ASSERT_EQ(soup->triangles.size(), 2u + 3u + 1u);
  // The pentagon (points 1 4 5 2 6, its last corner -1) as a fan; the triangle -5 -3 -2.
  EXPECT_EQ(soup->triangles[4], (std::array<int, 3>{1, 2, 6}));
  EXPECT_EQ(soup->triangles[5], (std::array<int, 3>{2, 4, 5}));
  ASSERT_TRUE(soup->has_texture());
  ASSERT_EQ(soup->textures.size(), 1u);
  EXPECT_EQ(soup->textures[0].size(), cv::Size(16, 8));
  EXPECT_EQ(soup->textures[0].type(), CV_8UC3);
  EXPECT_EQ(soup->triangle_texture, (std::vector<int>{0, 0, -1, -1, -1, -1}));
  EXPECT_EQ(soup->corner_uv[0][1], cv::Vec2f(1, 0));
}

TEST(TriangleSoup, DefectsOpenMeshDropsArriveIntact) {
  TempDir dir;
  // Two triangles on edge 0-1, a duplicate, a fin (third face on edge 0-1), a repeated corner,
  // a flipped face, a NaN point and an unreferenced point.
  write_text(dir / "bad.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 1 1 0\nv nan 0 0\nv 5 5 5\n"
             "f 1 2 3\nf 2 1 4\nf 1 2 3\nf 1 2 5\nf 2 2 3\nf 6 3 2\nf 7 1 3\n");
  auto soup = read_triangle_soup(dir / "bad.obj");
  ASSERT_TRUE(soup.is_ok()) << soup.status().message();
  EXPECT_EQ(soup->points.size(), 8u);
  EXPECT_EQ(soup->triangles.size(), 7u);
  EXPECT_TRUE(std::isnan(soup->points[6][0]));
  EXPECT_EQ(soup->triangles[4], (std::array<int, 3>{1, 1, 2}));
  // OpenMesh's importer loses or detaches some of these; the soup is what the file says.
  auto mesh = read_mesh(dir / "bad.obj");
  if (mesh.is_ok()) {
    EXPECT_LT(mesh->n_faces(), 7u);
  }
}

TEST(TriangleSoup, PlyRoundTripBinaryWithColoursTexcoordsAndNaN) {
  TempDir dir;
  TriangleSoup soup;
  soup.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, NAN}};
  soup.colors = {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 1}, {1, 1, 1, 1}};
  soup.triangles = {{0, 1, 2}, {1, 3, 2}, {0, 1, 2}};
  soup.texture_paths = {dir / "tex.png"};
  soup.triangle_texture = {0, 0, 0};
  soup.corner_uv = {{cv::Vec2f(0, 0), cv::Vec2f(1, 0), cv::Vec2f(0, 1)},
                    {cv::Vec2f(1, 0), cv::Vec2f(1, 1), cv::Vec2f(0, 1)},
                    {cv::Vec2f(0, 0), cv::Vec2f(0.5f, 0), cv::Vec2f(0, 0.5f)}};
  ASSERT_TRUE(write_image(dir / "tex.png", cv::Mat(4, 4, CV_8U, cv::Scalar(128))).is_ok());
  for (const char* name : {"soup.ply", "soup.obj"}) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(write_triangle_soup(dir / name, soup).is_ok());
    auto back = read_triangle_soup(dir / name);
    ASSERT_TRUE(back.is_ok()) << back.status().message();
    ASSERT_EQ(back->points.size(), 4u);
    EXPECT_EQ(back->points[1], soup.points[1]);
    EXPECT_TRUE(std::isnan(back->points[3][2]));
    EXPECT_EQ(back->triangles, soup.triangles);
    ASSERT_EQ(back->colors.size(), 4u);
    EXPECT_NEAR(back->colors[1][1], 1.0f, 1e-6);
    ASSERT_TRUE(back->has_texture());
    EXPECT_EQ(back->textures[0].type(), CV_8UC3);  // grey PNG as BGR
    EXPECT_EQ(back->corner_uv[2][1], cv::Vec2f(0.5f, 0));
  }
}

TEST(TriangleSoup, AsciiAndBigEndianPly) {
  TempDir dir;
  write_text(dir / "a.ply",
             "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
             "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
             "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
             "0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 0 10 10 10\n"
             "4 0 1 2 3\n3 0 0 1\n");
  auto a = read_triangle_soup(dir / "a.ply");
  ASSERT_TRUE(a.is_ok()) << a.status().message();
  EXPECT_EQ(a->triangles.size(), 3u);
  EXPECT_EQ(a->split_polygons, 1);
  EXPECT_EQ(a->triangles[2], (std::array<int, 3>{0, 0, 1}));  // kept as in the file
  EXPECT_NEAR(a->colors[2][2], 1.0f, 1e-6);

  std::string big =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\n"
      "property double y\nproperty double z\nelement face 1\n"
      "property list uchar uint vertex_indices\nend_header\n";
  auto put_be = [&](const void* data, size_t size) {
    const char* b = static_cast<const char*>(data);
    for (size_t i = 0; i < size; ++i) big.push_back(b[size - 1 - i]);
  };
  const double xyz[9] = {0, 0, 0, 2, 0, 0, 0, 3, 0};
  for (double v : xyz) put_be(&v, 8);
  big.push_back(3);
  for (uint32_t i : {0u, 1u, 2u}) put_be(&i, 4);
  write_text(dir / "b.ply", big);
  auto b = read_triangle_soup(dir / "b.ply");
  ASSERT_TRUE(b.is_ok()) << b.status().message();
  EXPECT_EQ(b->points[2], Mesh::Point(0, 3, 0));
  EXPECT_EQ(b->triangles[0], (std::array<int, 3>{0, 1, 2}));
}

TEST(TriangleSoup, MissingTextureIsANoteNotAnError) {
  TempDir dir;
  write_text(dir / "m.mtl", "newmtl a\nmap_Kd gone.jpg\n");
  write_text(dir / "m.obj",
             "mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\n");
  auto soup = read_triangle_soup(dir / "m.obj");
  ASSERT_TRUE(soup.is_ok()) << soup.status().message();
  EXPECT_FALSE(soup->has_texture());
  ASSERT_FALSE(soup->notes.empty());
  EXPECT_TRUE(contains(soup->notes[0], "gone.jpg")) << soup->notes[0];
}

TEST(TriangleSoup, BadFilesFailNamingTheFileAndWhere) {
  TempDir dir;
  struct Case {
    std::string file, text, expect;
  };
  const std::vector<Case> cases = {
      {"empty.obj", "", "empty.obj: empty file"},
      {"blank.ply", "\n \n", "blank.ply: empty file"},
      {"cloud.obj", "v 0 0 0\nv 1 0 0\n", "cloud.obj: 2 vertices but no faces"},
      {"nothing.obj", "# just a comment\n", "nothing.obj: no vertices"},
      {"range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "range.obj: line 4: corner '9'"},
      {"word.obj", "v 0 zero 0\n", "word.obj: line 1: 'zero' is not a number"},
      {"cloud.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n0 0 0\n",
       "cloud.ply: 1 vertices but no faces"},
      {"range.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
       "range.ply: face 0 refers to point 7, the file has 3"},
      {"short.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 30\nproperty float x\n"
       "property float y\nproperty float z\nend_header\n\x01\x02",
       "short.ply: truncated"},
      {"head.stl", "solid x\n", "unknown mesh format"},
  };
  for (const Case& c : cases) {
    write_text(dir / c.file, c.text);
    auto soup = read_triangle_soup(dir / c.file);
    ASSERT_FALSE(soup.is_ok()) << c.file;
    EXPECT_TRUE(contains(soup.status().message(), c.expect))
        << c.file << ": " << soup.status().message();
  }
  EXPECT_TRUE(contains(read_triangle_soup(dir / "missing.ply").status().message(),
                       "missing.ply: no such file"));
  EXPECT_FALSE(read_triangle_soup(dir / "empty.obj", {.scale = 0}).is_ok());
}

}  // namespace
}  // namespace gvkit
