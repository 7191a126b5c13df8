// `gvkit facemap clean` as a user runs it: ICT meshes and a synthetic scan in, 4-boundary faces
// out; landmarks from a folder of other tools' files; a bad frame is reported and skipped; bad
// options are rejected.
#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/face_landmarks_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "gvkit/core/mesh_topology.hpp"
#include "gvkit/core/npy_io.hpp"
#include "gvkit/facemap/synthetic_face_scan.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::run_gvkit;
using testing::TempDir;

TEST(CliFacemapClean, MeshesInFacesOutBadFrameSkipped) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen"});
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  TempDir in, out;
  for (int i = 0; i < 2; ++i) {
    const auto positions = model->evaluate({{"jawOpen", 0.3 * i}});
    ASSERT_TRUE(write_mesh(frame_path(in.path(), i, ".ply"), model->face_mesh(positions)).is_ok());
    FaceLandmarks landmarks;
    for (int v : model->landmark_vertices()) landmarks.points_mm.emplace_back(positions[v]);
    ASSERT_TRUE(
        write_face_landmarks(frame_path(in.path(), i, ".landmarks.json"), landmarks).is_ok());
  }
  // Frame 2: a mesh without its landmarks file, and detection off (--no-detect).
  ASSERT_TRUE(
      write_mesh(frame_path(in.path(), 2, ".ply"), model->face_mesh(model->neutral_mm())).is_ok());

  auto r = run_gvkit("facemap clean " + in.path().string() + " -o " + out.path().string() +
                     " --no-detect");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("frame_000002.landmarks.json"), std::string::npos) << r.output;
  for (int i = 0; i < 2; ++i) {
    auto mesh = read_mesh(frame_path(out.path(), i, ".ply"));
    ASSERT_TRUE(mesh.is_ok()) << mesh.status().message();
    const MeshTopology t = mesh_topology(*mesh);
    EXPECT_EQ(t.components, 1);
    EXPECT_EQ(t.genus, 0);
    EXPECT_EQ(t.boundary_loops, 4);
    auto landmarks = read_face_landmarks(frame_path(out.path(), i, ".landmarks.json"));
    ASSERT_TRUE(landmarks.is_ok());
    EXPECT_EQ(landmarks->points_mm.size(), 68u);
  }
  EXPECT_FALSE(std::filesystem::exists(frame_path(out.path(), 2, ".ply")));
  auto stats = read_json(out / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["summary"]["ok"], 2);
  EXPECT_EQ((*stats)["summary"]["failed"], 1);
  EXPECT_EQ((*stats)["frames"][2]["ok"], false);
  EXPECT_TRUE((*stats)["options"].contains("radius_mm"));
}

TEST(CliFacemapClean, MeshLandmarksFromAFolderInOtherFormats) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen"});
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  TempDir in, marks, out;
  // Frame 0: all 68 points as a float32 .npy; frame 1: the 51 without the jaw as a .csv.
  for (int i = 0; i < 2; ++i) {
    const auto positions = model->evaluate({{"jawOpen", 0.3 * i}});
    ASSERT_TRUE(write_mesh(frame_path(in.path(), i, ".obj"), model->face_mesh(positions)).is_ok());
    std::vector<double> values;
    std::string csv = "x,y,z\n";
    for (int k = 0; k < 68; ++k) {
      const cv::Vec3d& p = positions[model->landmark_vertices()[k]];
      values.insert(values.end(), {p[0], p[1], p[2]});
      if (k >= 17)
        csv +=
            std::to_string(p[0]) + "," + std::to_string(p[1]) + "," + std::to_string(p[2]) + "\n";
    }
    if (i == 0)
      ASSERT_TRUE(write_npy(frame_path(marks.path(), i, ".npy"), {68, 3}, values, NpyType::kFloat32)
                      .is_ok());
    else
      ASSERT_TRUE(write_file_atomically(frame_path(marks.path(), i, ".csv"), csv).is_ok());
  }
  auto r = run_gvkit("facemap clean " + in.path().string() + " -o " + out.path().string() +
                     " --landmarks " + marks.path().string() + " --no-detect");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto stats = read_json(out / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["summary"]["ok"], 2);
  EXPECT_EQ((*stats)["frames"][0]["mesh_input"]["landmarks"]["file"], "frame_000000.npy");
  EXPECT_EQ((*stats)["frames"][1]["mesh_input"]["landmarks"]["file"], "frame_000001.csv");
  EXPECT_EQ((*stats)["frames"][1]["mesh_input"]["landmarks"]["points"], 51);
  for (int i = 0; i < 2; ++i) {
    auto mesh = read_mesh(frame_path(out.path(), i, ".ply"));
    ASSERT_TRUE(mesh.is_ok()) << mesh.status().message();
    EXPECT_EQ(mesh_topology(*mesh).boundary_loops, 4);
  }
}

TEST(CliFacemapClean, SyntheticScanWithDetectedLandmarks) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  if (!std::filesystem::exists("/usr/share/dlib/shape_predictor_68_face_landmarks.dat"))
    GTEST_SKIP() << "dlib model absent (package libdlib-data)";
  auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen"});
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  TempDir in, out;
  const auto synthetic = facemap::render_synthetic_face_scan(*model, model->neutral_mm(),
                                                             {.size_px = 176, .pixel_mm = 1.2});
  ASSERT_TRUE(write_range_scan_exr(frame_path(in.path(), 0, ".exr"), synthetic.scan).is_ok());
  auto r = run_gvkit("facemap clean " + in.path().string() + " -o " + out.path().string() +
                     " --radius 60");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto mesh = read_mesh(frame_path(out.path(), 0, ".ply"));
  ASSERT_TRUE(mesh.is_ok());
  EXPECT_TRUE(mesh->has_vertex_colors());
  EXPECT_EQ(mesh_topology(*mesh).boundary_loops, 4);
  auto landmarks = read_face_landmarks(frame_path(out.path(), 0, ".landmarks.json"));
  ASSERT_TRUE(landmarks.is_ok());
  EXPECT_EQ(landmarks->points_px.size(), 68u);
  // Per frame: how landmarks were moved onto the mesh (bounded) and the mask's step timers.
  auto stats = read_json(out / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  const auto& frame = (*stats)["frames"][0];
  EXPECT_LE(frame["landmarks_snapped"]["max_px"].get<double>(), 10.0);
  EXPECT_TRUE(frame["ms"].contains("mask_steps"));
  EXPECT_EQ((*stats)["options"]["landmark_max_snap_mm"], 8.0);
}

TEST(CliFacemapClean, BadInputAndOptionsAreRejected) {
  TempDir empty, out;
  auto r = run_gvkit("facemap clean " + empty.path().string() + " -o " + out.path().string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("no frame_NNNNNN"), std::string::npos) << r.output;
  r = run_gvkit("facemap clean " + empty.path().string() + " -o " + out.path().string() +
                " --radius -5");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("radius"), std::string::npos) << r.output;
  r = run_gvkit("facemap clean " + empty.path().string() + " -o " + out.path().string() +
                " --max-landmark-snap -1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("landmark_max_snap_mm"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace gvkit
