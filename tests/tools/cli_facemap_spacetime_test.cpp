// The Spacetime faces through `facemap landmarks`, `facemap clean --same-vertices` and `facemap
// map`: landmarks from a shaded render of real meshes without any, one output vertex layout for
// both frames, no flipped triangle in either map;
// a mesh without a face is an error naming it.
#include <filesystem>

#include <gtest/gtest.h>

#include "gvkit/core/face_landmarks_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
namespace fs = std::filesystem;
using testing::run_gvkit;
using testing::TempDir;

TEST(CliFacemapSpacetime, LandmarksThenCleanWithSameVertices) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  if (!fs::exists("/usr/share/dlib/shape_predictor_68_face_landmarks.dat"))
    GTEST_SKIP() << "dlib model absent (package libdlib-data)";
  TempDir in, out;
  const char* names[] = {"neutral.ply", "smile.ply"};
  for (int i = 0; i < 2; ++i) {
    fs::copy_file(data / "spacetime-faces" / names[i], frame_path(in.path(), i, ".ply"));
    const fs::path json = frame_path(in.path(), i, ".landmarks.json");
    auto r = run_gvkit("facemap landmarks " + frame_path(in.path(), i, ".ply").string() + " -o " +
                       json.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    auto landmarks = read_face_landmarks(json);
    ASSERT_TRUE(landmarks.is_ok()) << landmarks.status().message();
    ASSERT_EQ(landmarks->points_mm.size(), 68u);
    // The camera was about 1.2 m away: the points lie on the face, nose tip nearest the camera
    // among the nose, eyes and mouth.
    const auto& p = landmarks->points_mm;
    for (const auto& q : p) EXPECT_GT(q[2], 1000.0f);
    EXPECT_LT(p[30][2], p[36][2]);
    EXPECT_LT(p[30][2], p[45][2]);
    EXPECT_LT(p[30][2], p[57][2]);
  }
  auto r = run_gvkit("facemap clean " + in.path().string() + " -o " + out.path().string() +
                     " --same-vertices");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto a = read_mesh(frame_path(out.path(), 0, ".ply"));
  auto b = read_mesh(frame_path(out.path(), 1, ".ply"));
  ASSERT_TRUE(a.is_ok() && b.is_ok());
  EXPECT_EQ(a->n_vertices(), b->n_vertices());
  EXPECT_EQ(a->n_faces(), b->n_faces());
  auto stats = read_json(out.path() / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  const auto& frame1 = (*stats)["frames"][1];
  ASSERT_TRUE(frame1.contains("transferred_from_first_frame")) << frame1.dump();
  // The smile moved the mouth: the carried face is not the neutral one.
  double moved = 0.0;
  for (auto v : a->vertices()) moved = std::max(moved, (a->point(v) - b->point(v)).norm());
  EXPECT_GT(moved, 2.0);
  // Both frames map onto the canonical domain without a flipped triangle.
  const fs::path map = out.path() / "map";
  r = run_gvkit("facemap map " + out.path().string() + " -o " + map.string() +
                " --size 48x48 --same-vertices");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto map_stats = read_json(map / "stats.json");
  ASSERT_TRUE(map_stats.is_ok());
  EXPECT_EQ((*map_stats)["summary"]["mapped"], 2);
  EXPECT_EQ((*map_stats)["summary"]["flipped_total"], 0);
}

TEST(CliFacemapSpacetime, NoFaceIsAnErrorNamingTheMesh) {
  TempDir dir;
  Mesh mesh;
  std::vector<Mesh::VertexHandle> v;
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 10; ++x) v.push_back(mesh.add_vertex(Mesh::Point(x * 5.0, y * 5.0, 0)));
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 9; ++x) {
      mesh.add_face(v[y * 10 + x], v[y * 10 + x + 1], v[(y + 1) * 10 + x + 1]);
      mesh.add_face(v[y * 10 + x], v[(y + 1) * 10 + x + 1], v[(y + 1) * 10 + x]);
    }
  const fs::path path = dir.path() / "plane.ply";
  ASSERT_TRUE(write_mesh(path, mesh).is_ok());
  auto r = run_gvkit("facemap landmarks " + path.string() + " -o " +
                     (dir.path() / "plane.landmarks.json").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("plane.ply"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no face"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace gvkit
