// `gvkit facemap clean` on bad mesh input: an empty file, a point cloud, a mesh whose faces are
// all degenerate, landmarks of another mesh, 2-D landmarks on a mesh without a texture, a bad
// landmark file: each ends in a message naming the file; nothing an earlier run wrote is lost,
// and --resume recomputes a failed frame once its input has been fixed.
#include <filesystem>

#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/face_landmarks_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "gvkit/core/npy_io.hpp"
#include "gvkit/core/triangle_soup.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
namespace fs = std::filesystem;
using testing::contains;
using testing::run_gvkit;
using testing::TempDir;

// A 200 x 200 mm grid of 10 mm squares (a surface of a face's size that is no face).
TriangleSoup plate() {
  TriangleSoup soup;
  for (int y = 0; y <= 20; ++y)
    for (int x = 0; x <= 20; ++x) soup.points.emplace_back(10.0 * x, 10.0 * y, 0.0);
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 20; ++x) {
      const int a = y * 21 + x;
      soup.triangles.push_back({a, a + 1, a + 22});
      soup.triangles.push_back({a, a + 22, a + 21});
    }
  return soup;
}

std::string clean(const fs::path& input, const fs::path& out, const std::string& extra = "") {
  auto r = run_gvkit("facemap clean " + input.string() + " -o " + out.string() + " " + extra);
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_FALSE(contains(r.output, "internal")) << r.output;
  return r.output;
}

TEST(CliFacemapBadMeshInput, EveryBadInputIsNamedInItsMessage) {
  TempDir dir;
  const fs::path out = dir / "out";
  ASSERT_TRUE(write_file_atomically(dir / "empty.obj", "").is_ok());
  EXPECT_TRUE(contains(clean(dir / "empty.obj", out), "empty.obj: empty file"));

  ASSERT_TRUE(write_file_atomically(dir / "cloud.ply",
                                    "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                    "property float y\nproperty float z\nelement face 0\n"
                                    "property list uchar int vertex_indices\nend_header\n"
                                    "0 0 0\n1 0 0\n")
                  .is_ok());
  EXPECT_TRUE(contains(clean(dir / "cloud.ply", out), "cloud.ply: 2 vertices but no faces"));

  TriangleSoup flat;
  flat.points = {{0, 0, 0}, {100, 0, 0}, {200, 0, 0}, {0, 0, 0}};
  flat.triangles = {{0, 1, 2}, {0, 3, 1}, {1, 1, 2}};
  ASSERT_TRUE(write_triangle_soup(dir / "flat.obj", flat).is_ok());
  EXPECT_TRUE(contains(clean(dir / "flat.obj", out), "flat.obj: no face is left after the repair"));

  // Landmarks of another mesh: 68 points 300 mm in front of the plate.
  ASSERT_TRUE(write_triangle_soup(dir / "plate.ply", plate()).is_ok());
  std::vector<double> far;
  for (int i = 0; i < 68; ++i)
    for (double v : {100.0 + i, 100.0 - i, 300.0}) far.push_back(v);
  ASSERT_TRUE(write_npy(dir / "other.npy", {68, 3}, far).is_ok());
  const std::string other =
      clean(dir / "plate.ply", out, "--landmarks " + (dir / "other.npy").string());
  EXPECT_TRUE(contains(other, "plate.ply (landmarks other.npy): landmark 30 lies 300 mm off"))
      << other;

  // 2-D points, and the plate has no texture image they could be pixels of.
  std::string rows;
  for (int i = 0; i < 68; ++i) rows += std::to_string(10 + i) + " " + std::to_string(20 + i) + "\n";
  ASSERT_TRUE(write_file_atomically(dir / "pixels.txt", rows).is_ok());
  const std::string pixels =
      clean(dir / "plate.ply", out, "--landmarks " + (dir / "pixels.txt").string());
  EXPECT_TRUE(contains(pixels, "pixels.txt: 2-D points on a mesh must be pixels of its texture"))
      << pixels;

  // A bad landmark file stops the run before anything is written.
  std::vector<double> nan_points(68 * 3, 1.0);
  nan_points[100] = NAN;
  ASSERT_TRUE(write_npy(dir / "nan.npy", {68, 3}, nan_points).is_ok());
  const fs::path untouched = dir / "untouched";
  EXPECT_TRUE(
      contains(clean(dir / "plate.ply", untouched, "--landmarks " + (dir / "nan.npy").string()),
               "nan.npy: point 33 is not finite"));
  EXPECT_FALSE(fs::exists(untouched));

  // Units that are not one, both ways of giving them, a missing landmark file.
  EXPECT_TRUE(
      contains(clean(dir / "plate.ply", out, "--units inch"), "--units must be mm, cm or m"));
  EXPECT_TRUE(contains(clean(dir / "plate.ply", out, "--units cm --scale 10"), "give one"));
  EXPECT_TRUE(contains(clean(dir / "plate.ply", out, "--landmarks " + (dir / "gone.npy").string()),
                       "gone.npy: no such file or folder"));
  ASSERT_TRUE(write_file_atomically(dir / "notes.txt", "a head\n").is_ok());
  EXPECT_TRUE(
      contains(clean(dir / "notes.txt", out), "notes.txt: not a range scan (.exr) or a mesh"));
}

TEST(CliFacemapBadMeshInput, EarlierResultsAreKeptAndAFixedFrameIsResumed) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen"});
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  TempDir in, out;
  std::vector<FaceLandmarks> truth(2);
  for (int i = 0; i < 2; ++i) {
    const auto positions = model->evaluate({{"jawOpen", 0.25 * i}});
    ASSERT_TRUE(write_mesh(frame_path(in.path(), i, ".ply"), model->face_mesh(positions)).is_ok());
    for (int v : model->landmark_vertices()) truth[i].points_mm.emplace_back(positions[v]);
    ASSERT_TRUE(
        write_face_landmarks(frame_path(in.path(), i, ".landmarks.json"), truth[i]).is_ok());
  }
  auto r = run_gvkit("facemap clean " + in.path().string() + " -o " + out.path().string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto stats_before = read_file(out / "stats.json");
  const auto mesh_before = read_file(frame_path(out.path(), 1, ".ply"));
  ASSERT_TRUE(stats_before.is_ok() && mesh_before.is_ok());

  // A bad --landmarks file: refused before anything in the output folder changes.
  ASSERT_TRUE(write_npy(in / "bad.npy", {68, 4}, std::vector<double>(68 * 4, 1.0)).is_ok());
  r = run_gvkit("facemap clean " + in.path().string() + " -o " + out.path().string() +
                " --landmarks " + (in / "bad.npy").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.output, "bad.npy: array of shape (68, 4)")) << r.output;
  EXPECT_EQ(read_file(out / "stats.json").value(), stats_before.value());
  EXPECT_EQ(read_file(frame_path(out.path(), 1, ".ply")).value(), mesh_before.value());

  // Frame 1's landmarks replaced by another mesh's (moved 200 mm): that frame fails naming both
  // files, frame 0 is kept from the earlier run, frame 1's earlier mesh stays on disk.
  FaceLandmarks moved = truth[1];
  for (auto& p : moved.points_mm) p[2] += 200.0f;
  ASSERT_TRUE(write_face_landmarks(frame_path(in.path(), 1, ".landmarks.json"), moved).is_ok());
  r = run_gvkit("facemap clean " + in.path().string() + " -o " + out.path().string() + " --resume");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output,
                       "frame_000001.ply (landmarks frame_000001.landmarks.json): "
                       "landmark 30 lies 200 mm off the mesh"))
      << r.output;
  auto stats = read_json(out / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["summary"]["kept_from_earlier_run"], 1);
  EXPECT_EQ((*stats)["frames"][1]["ok"], false);
  EXPECT_EQ(read_file(frame_path(out.path(), 1, ".ply")).value(), mesh_before.value());

  // Fixed: --resume keeps frame 0 and computes frame 1 again (its landmark file changed).
  ASSERT_TRUE(write_face_landmarks(frame_path(in.path(), 1, ".landmarks.json"), truth[1]).is_ok());
  r = run_gvkit("facemap clean " + in.path().string() + " -o " + out.path().string() + " --resume");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  stats = read_json(out / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["summary"]["ok"], 2);
  EXPECT_EQ((*stats)["summary"]["kept_from_earlier_run"], 1);
  EXPECT_EQ((*stats)["frames"][1]["ok"], true);
}

}  // namespace
}  // namespace gvkit
