#include "gvkit/core/mesh_io.hpp"

#include <atomic>
#include <thread>

#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/mesh_topology.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::TempDir;

// An n x n vertex grid in the z = 0 plane, two triangles per quad, with colours and texcoords.
Mesh grid_mesh(int n) {
  Mesh mesh;
  mesh.request_vertex_colors();
  mesh.request_vertex_texcoords2D();
  std::vector<Mesh::VertexHandle> v;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      auto h = mesh.add_vertex(Mesh::Point(x, y, 0.5 * x * y));
      mesh.set_color(h, Mesh::Color(x / float(n), y / float(n), 0.25f, 1.0f));
      mesh.set_texcoord2D(h, Mesh::TexCoord2D(x / double(n - 1), y / double(n - 1)));
      v.push_back(h);
    }
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      auto a = v[y * n + x], b = v[y * n + x + 1], c = v[(y + 1) * n + x],
           d = v[(y + 1) * n + x + 1];
      mesh.add_face(a, b, d);
      mesh.add_face(a, d, c);
    }
  return mesh;
}

TEST(MeshTopology, GridIsADiskAndAHoleAddsALoop) {
  Mesh mesh = grid_mesh(6);
  MeshTopology t = mesh_topology(mesh);
  EXPECT_EQ(t.vertices, 36);
  EXPECT_EQ(t.faces, 50);
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.boundary_loops, 1);
  EXPECT_EQ(t.genus, 0);
  EXPECT_EQ(t.boundary_loop_lengths.front(), 20);
  // Remove the two triangles of an interior quad: a second boundary loop of 4 edges.
  mesh.request_face_status();
  int removed = 0;
  for (auto f : mesh.faces()) {
    auto c = mesh.calc_face_centroid(f);
    if (c[0] > 2 && c[0] < 3 && c[1] > 2 && c[1] < 3) {
      mesh.delete_face(f, false);
      ++removed;
    }
  }
  mesh.garbage_collection();
  ASSERT_EQ(removed, 2);
  t = mesh_topology(mesh);
  EXPECT_EQ(t.boundary_loops, 2);
  EXPECT_EQ(t.genus, 0);
  EXPECT_EQ(t.boundary_loop_lengths.back(), 4);
}

TEST(MeshIo, PlyAndObjRoundTrip) {
  TempDir dir;
  const Mesh mesh = grid_mesh(5);
  for (const char* name : {"m.ply", "m_ascii.ply", "m.obj"}) {
    MeshWriteOptions options;
    options.binary = std::string(name) != "m_ascii.ply";
    ASSERT_TRUE(write_mesh(dir / name, mesh, options).is_ok()) << name;
    auto back = read_mesh(dir / name);
    ASSERT_TRUE(back.is_ok()) << back.status().message();
    ASSERT_EQ(back->n_vertices(), mesh.n_vertices());
    ASSERT_EQ(back->n_faces(), mesh.n_faces());
    for (auto v : mesh.vertices()) EXPECT_LT((back->point(v) - mesh.point(v)).norm(), 1e-5) << name;
    if (std::string(name) != "m.obj") {
      ASSERT_TRUE(back->has_vertex_colors()) << name;
      for (auto v : mesh.vertices())
        EXPECT_LT((back->color(v) - mesh.color(v)).norm(), 1e-2) << name;
    } else {
      ASSERT_TRUE(back->has_vertex_texcoords2D());
      for (auto v : mesh.vertices())
        EXPECT_LT((back->texcoord2D(v) - mesh.texcoord2D(v)).norm(), 1e-5);
    }
  }
}

// gvkit's binary PLY serializer writes OpenMesh's bytes: with and without normals, texture
// coordinates and colours, and on a mesh where OpenMesh rejected a non-manifold face.
TEST(MeshIo, DirectBinaryPlyEqualsOpenMeshsWriter) {
  TempDir dir;
  Mesh mesh = grid_mesh(9);
  mesh.request_vertex_normals();
  mesh.request_face_normals();
  mesh.update_normals();
  // A fan whose apex already has two separate boundary gaps: OpenMesh refuses a face that would
  // close a third one at a complex vertex, and keeps the rest.
  const auto extra = mesh.add_vertex(Mesh::Point(-3, -3, 1));
  mesh.add_face(Mesh::VertexHandle(0), extra, Mesh::VertexHandle(9));
  for (int combo = 0; combo < 8; ++combo) {
    MeshWriteOptions direct;
    direct.vertex_normals = combo & 1;
    direct.vertex_texcoords = combo & 2;
    direct.vertex_colors = combo & 4;
    MeshWriteOptions openmesh = direct;
    openmesh.openmesh_writer = true;
    ASSERT_TRUE(write_mesh(dir / "direct.ply", mesh, direct).is_ok());
    ASSERT_TRUE(write_mesh(dir / "openmesh.ply", mesh, openmesh).is_ok());
    const auto a = read_file(dir / "direct.ply"), b = read_file(dir / "openmesh.ply");
    ASSERT_TRUE(a.is_ok() && b.is_ok());
    EXPECT_EQ(a.value(), b.value()) << "options " << combo;
  }
}

TEST(MeshIo, ScaleOptionConvertsUnits) {
  TempDir dir;
  ASSERT_TRUE(write_mesh(dir / "m.ply", grid_mesh(3)).is_ok());
  auto back = read_mesh(dir / "m.ply", MeshReadOptions{10.0});
  ASSERT_TRUE(back.is_ok());
  EXPECT_NEAR(back->point(Mesh::VertexHandle(8))[0], 20.0, 1e-9);
}

TEST(MeshIo, BadFilesAreRejectedWithTheirName) {
  TempDir dir;
  EXPECT_EQ(read_mesh(dir / "none.ply").status().code(), StatusCode::kNotFound);
  EXPECT_EQ(read_mesh(dir / "m.xyz").status().code(), StatusCode::kNotFound);
  ASSERT_TRUE(write_file_atomically(dir / "m.xyz", "1 2 3").is_ok());
  EXPECT_EQ(read_mesh(dir / "m.xyz").status().code(), StatusCode::kUnsupported);
  ASSERT_TRUE(write_file_atomically(dir / "empty.ply", "").is_ok());
  EXPECT_EQ(read_mesh(dir / "empty.ply").status().code(), StatusCode::kCorruptData);
  ASSERT_TRUE(
      write_file_atomically(dir / "junk.ply", "ply\nformat ascii 1.0\nelement vertex 3\n").is_ok());
  auto junk = read_mesh(dir / "junk.ply");
  ASSERT_FALSE(junk.is_ok());
  EXPECT_NE(junk.status().message().find("junk.ply"), std::string::npos);
  ASSERT_TRUE(write_mesh(dir / "full.ply", grid_mesh(20)).is_ok());
  const std::string bytes = *read_file(dir / "full.ply");
  ASSERT_TRUE(write_file_atomically(dir / "cut.ply", bytes.substr(0, bytes.size() / 2)).is_ok());
  auto cut = read_mesh(dir / "cut.ply");
  ASSERT_FALSE(cut.is_ok()) << "a truncated PLY must not read as a (shorter) mesh";
  EXPECT_NE(cut.status().message().find("truncated"), std::string::npos);
}

TEST(MeshIo, ConcurrentReadsAndWritesAreSafe) {
  TempDir dir;
  const Mesh mesh = grid_mesh(30);
  ASSERT_TRUE(write_mesh(dir / "m.ply", mesh).is_ok());
  std::vector<std::thread> threads;
  std::atomic<int> good{0};
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int k = 0; k < 10; ++k) {
        auto back = read_mesh(dir / "m.ply");
        if (back.is_ok() && back->n_faces() == mesh.n_faces()) ++good;
        const auto out = dir / ("w" + std::to_string(t) + ".ply");
        if (write_mesh(out, mesh).is_ok()) ++good;
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(good.load(), 80);
}

TEST(MeshIo, IctNeutralFaceHasItsDocumentedVertexCount) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto mesh = read_mesh(data / "ict-facekit" / "generic_neutral_mesh.obj");
  ASSERT_TRUE(mesh.is_ok()) << mesh.status().message();
  EXPECT_EQ(mesh->n_vertices(), 26719u);
  EXPECT_TRUE(mesh->has_vertex_texcoords2D());
}

TEST(MeshIo, SpacetimeFaceIsOneDiskWithOneHole) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto mesh = read_mesh(data / "spacetime-faces" / "neutral.ply");
  ASSERT_TRUE(mesh.is_ok()) << mesh.status().message();
  EXPECT_EQ(mesh->n_vertices(), 7118u);
  const MeshTopology t = mesh_topology(*mesh);
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.boundary_loops, 2);
  EXPECT_EQ(t.genus, 0);
}

}  // namespace
}  // namespace gvkit
