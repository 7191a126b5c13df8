// `gvkit facemap clean` on raw head meshes as a new user brings them: one OBJ or PLY of a whole
// textured head (the ICT model with head, neck and sockets), with injected defects (duplicate
// faces, fins on edges, floating islands, a flipped patch, zero-area faces, NaN vertices,
// unreferenced vertices, a longer neck, spikes of 'hair'), in centimetres, with landmarks from a
// 3-D .npy, from 2-D texture pixels of a 51-point .txt, or detected on the textured render.
// Every defect is repaired and counted; the face comes out with its 4 boundaries.
#include <filesystem>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/face_landmarks_io.hpp"
#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "gvkit/core/mesh_topology.hpp"
#include "gvkit/core/npy_io.hpp"
#include "gvkit/core/triangle_soup.hpp"
#include "gvkit/facemap/synthetic_head_mesh.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
namespace fs = std::filesystem;
using testing::contains;
using testing::run_gvkit;
using testing::TempDir;

// How many of each defect were injected (what the repair must count).
struct Injected {
  int duplicates = 0, fins = 0, islands = 0, flipped = 0, zero_area = 0, nan_faces = 0;
  int unreferenced = 0, spikes = 0, neck_rings = 0;
  std::vector<cv::Vec3d> debris;  // points of the neck rings, fins, spikes and islands
};

cv::Vec3d xyz(const Mesh::Point& p) { return {p[0], p[1], p[2]}; }

void add_face(TriangleSoup* soup, std::array<int, 3> t) {
  soup->triangles.push_back(t);
  soup->triangle_texture.push_back(-1);
  soup->corner_uv.push_back({});
}

// The head's defects, away from the face (all on the head & neck, vertices 9409-11247, or loose).
Injected inject_defects(TriangleSoup* soup) {
  Injected n;
  std::mt19937 random(27);
  const int original_faces = static_cast<int>(soup->triangles.size());
  auto head = [&](const std::array<int, 3>& t) {
    return t[0] >= 9409 && t[0] < 11248 && t[1] >= 9409 && t[1] < 11248 && t[2] >= 9409 &&
           t[2] < 11248;
  };
  // Which head faces touch which point (to keep defects apart).
  std::vector<int> used(soup->points.size(), 0);
  auto take = [&](const std::array<int, 3>& t) {
    for (int v : t)
      if (used[v]) return false;
    for (int v : t) used[v] = 1;
    return true;
  };
  std::vector<int> head_faces;
  for (int f = 0; f < original_faces; ++f)
    if (head(soup->triangles[f])) head_faces.push_back(f);
  std::shuffle(head_faces.begin(), head_faces.end(), random);
  size_t next = 0;
  auto next_free = [&]() {
    while (next < head_faces.size() && !take(soup->triangles[head_faces[next]])) ++next;
    return head_faces[next++];
  };
  // The back of the head: a flipped patch of the faces around one vertex's neighbourhood.
  {
    double min_z = 1e9;
    int seed = -1;
    for (int f : head_faces) {
      const double z = soup->points[soup->triangles[f][0]][2];
      if (z < min_z) min_z = z, seed = soup->triangles[f][0];
    }
    const Mesh::Point centre = soup->points[seed];
    for (int f : head_faces) {
      auto& t = soup->triangles[f];
      bool near = true;
      for (int v : t) near &= (soup->points[v] - centre).norm() < 45.0;
      if (!near) continue;
      for (int v : t) used[v] = 1;
      std::swap(t[1], t[2]);
      std::swap(soup->corner_uv[f][1], soup->corner_uv[f][2]);
      ++n.flipped;
    }
  }
  // A longer neck: three rings of 25 mm hung below the lowest boundary loop.
  {
    std::map<std::pair<int, int>, int> edges;  // directed edge -> count
    for (const auto& t : soup->triangles)
      for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
    std::vector<std::pair<int, int>> boundary;  // directed face edges with no twin
    double lowest = 1e9;
    for (const auto& [e, count] : edges)
      if (!edges.count({e.second, e.first}) && e.first < 14062) {
        boundary.push_back(e);
        lowest = std::min(lowest, soup->points[e.first][1]);
      }
    std::vector<std::pair<int, int>> neck;
    for (const auto& e : boundary)
      if (soup->points[e.first][1] < lowest + 40 && soup->points[e.second][1] < lowest + 40)
        neck.push_back(e);
    std::map<int, int> below;  // ring point below each point
    for (int ring = 0; ring < 3; ++ring) {
      std::map<int, int> next_below;
      auto lower = [&](int v) {
        auto it = next_below.find(v);
        if (it != next_below.end()) return it->second;
        Mesh::Point p = soup->points[v];
        p[1] -= 25.0;
        soup->points.push_back(p);
        n.debris.push_back(xyz(p));
        return next_below[v] = static_cast<int>(soup->points.size()) - 1;
      };
      std::vector<std::pair<int, int>> next_neck;
      for (const auto& [a, b] : neck) {
        const int a2 = lower(a), b2 = lower(b);
        add_face(soup, {b, a, a2});
        add_face(soup, {b, a2, b2});
        next_neck.emplace_back(a2, b2);
      }
      neck = next_neck;
    }
    n.neck_rings = 3;
  }
  // Duplicates, half of them with the opposite winding.
  for (int k = 0; k < 12; ++k) {
    auto t = soup->triangles[next_free()];
    if (k % 2) std::swap(t[1], t[2]);
    add_face(soup, t);
    ++n.duplicates;
  }
  // Fins: a third face on an interior edge, standing out of the surface.
  for (int k = 0; k < 8; ++k) {
    const auto t = soup->triangles[next_free()];
    const cv::Vec3d a = xyz(soup->points[t[0]]), b = xyz(soup->points[t[1]]);
    const cv::Vec3d apex =
        0.5 * (a + b) + cv::normalize((b - a).cross(xyz(soup->points[t[2]]) - a)) * 6.0;
    soup->points.emplace_back(apex[0], apex[1], apex[2]);
    n.debris.push_back(apex);
    add_face(soup, {t[0], t[1], static_cast<int>(soup->points.size()) - 1});
    ++n.fins;
  }
  // Zero-area faces: a new point on an existing one.
  for (int k = 0; k < 5; ++k) {
    const auto t = soup->triangles[next_free()];
    soup->points.push_back(soup->points[t[0]]);
    add_face(soup, {t[0], t[1], static_cast<int>(soup->points.size()) - 1});
    ++n.zero_area;
  }
  // NaN vertices: three head points made NaN (their faces are dropped: holes in the back).
  for (int k = 0; k < 3; ++k) {
    const int v = soup->triangles[next_free()][0];
    soup->points[v] = Mesh::Point(NAN, NAN, NAN);
    for (const auto& t : soup->triangles)
      if (t[0] == v || t[1] == v || t[2] == v) ++n.nan_faces;
  }
  // Spikes of hair on the scalp: a face replaced by a thin pyramid 30 mm tall.
  for (int k = 0; k < 10; ++k) {
    const int f = next_free();
    const auto t = soup->triangles[f];
    const cv::Vec3d a = xyz(soup->points[t[0]]), b = xyz(soup->points[t[1]]),
                    c = xyz(soup->points[t[2]]);
    const cv::Vec3d apex = (a + b + c) / 3.0 + cv::normalize((b - a).cross(c - a)) * 30.0;
    soup->points.emplace_back(apex[0], apex[1], apex[2]);
    n.debris.push_back(apex);
    const int p = static_cast<int>(soup->points.size()) - 1;
    soup->triangles[f] = {t[0], t[1], p};
    soup->triangle_texture[f] = -1;
    add_face(soup, {t[1], t[2], p});
    add_face(soup, {t[2], t[0], p});
    ++n.spikes;
  }
  // Islands: three loose pieces (scanner debris) of two triangles each.
  for (int k = 0; k < 3; ++k) {
    const int i0 = static_cast<int>(soup->points.size());
    const double x = 150.0 + 20 * k;
    for (const auto& p : {Mesh::Point(x, 0, 0), Mesh::Point(x + 4, 0, 0), Mesh::Point(x, 4, 0),
                          Mesh::Point(x + 4, 4, 1)}) {
      soup->points.push_back(p);
      n.debris.push_back(xyz(p));
    }
    add_face(soup, {i0, i0 + 1, i0 + 3});
    add_face(soup, {i0, i0 + 3, i0 + 2});
    ++n.islands;
  }
  // Unreferenced points.
  for (int k = 0; k < 7; ++k) soup->points.emplace_back(0.0, -500.0 - k, 0.0);
  n.unreferenced = 7;
  return n;
}

struct Fixture {
  facemap::SyntheticHead head;
  Injected injected;
  std::vector<cv::Vec3d> landmarks_mm;  // ground truth
};

Fixture make_fixture(const IctFaceModel& model) {
  Fixture f;
  f.head = facemap::synthetic_head_mesh(model, model.neutral_mm(), {.texture_px = 512});
  for (int v : model.landmark_vertices()) f.landmarks_mm.push_back(model.neutral_mm()[v]);
  f.injected = inject_defects(&f.head.soup);
  return f;
}

// Writes the soup (points divided by `unit_mm`) and its texture image into dir.
void write_head(const fs::path& path, TriangleSoup soup, double unit_mm) {
  for (auto& p : soup.points) p /= unit_mm;
  soup.texture_paths = {path.parent_path() / "head.png"};
  ASSERT_TRUE(write_triangle_soup(path, soup).is_ok());
  ASSERT_TRUE(write_image(path.parent_path() / "head.png", soup.textures[0]).is_ok());
}

nlohmann::json first_frame(const fs::path& out) {
  auto stats = read_json(out / "stats.json");
  EXPECT_TRUE(stats.is_ok());
  return stats.is_ok() ? (*stats)["frames"][0] : nlohmann::json();
}

// The cleaned face: one surface, genus 0, 4 boundaries, nothing of the neck, fins, spikes or
// islands; returns the mean distance of its eye and mouth landmarks (36-67) from the truth (mm).
double check_face(const fs::path& out, const std::vector<cv::Vec3d>& truth,
                  const std::vector<cv::Vec3d>& debris) {
  auto mesh = read_mesh(out / "frame_000000.ply");
  EXPECT_TRUE(mesh.is_ok());
  if (!mesh.is_ok()) return 1e9;
  const MeshTopology t = mesh_topology(*mesh);
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.genus, 0);
  EXPECT_EQ(t.boundary_loops, 4);
  double nearest = 1e9;
  for (auto v : mesh->vertices())
    for (const auto& d : debris) nearest = std::min(nearest, cv::norm(xyz(mesh->point(v)) - d));
  EXPECT_GT(nearest, 1.0);  // the face only
  auto landmarks = read_face_landmarks(out / "frame_000000.landmarks.json");
  EXPECT_TRUE(landmarks.is_ok());
  if (!landmarks.is_ok()) return 1e9;
  double sum = 0;
  for (int i = 36; i < 68; ++i) sum += cv::norm(cv::Vec3d(landmarks->points_mm[i]) - truth[i]);
  return sum / 32;
}

class CliFacemapRawMesh : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const fs::path data = testing::shared_data_dir();
    if (data.empty()) return;
    auto model = IctFaceModel::load(data / "ict-facekit", {"jawOpen"});
    ASSERT_TRUE(model.is_ok()) << model.status().message();
    fixture_ = new Fixture(make_fixture(*model));
  }
  static void TearDownTestSuite() {
    delete fixture_;
    fixture_ = nullptr;
  }
  static Fixture* fixture_;
};
Fixture* CliFacemapRawMesh::fixture_ = nullptr;

TEST_F(CliFacemapRawMesh, DefectiveHeadInCentimetresWith3dNpyLandmarks) {
  if (!fixture_) GTEST_SKIP() << "../shared/data is absent; this test needs it";
  const Fixture& f = *fixture_;
  TempDir dir;
  write_head(dir / "head.obj", f.head.soup, 10.0);
  std::vector<double> values;
  for (const auto& p : f.landmarks_mm)
    for (int k = 0; k < 3; ++k) values.push_back(p[k] / 10.0);
  ASSERT_TRUE(write_npy(dir / "head.npy", {68, 3}, values, NpyType::kFloat32).is_ok());

  // Without units the head (30 cm across) is 30 "mm": refused with the hint.
  auto r = run_gvkit("facemap clean " + (dir / "head.obj").string() + " -o " +
                     (dir / "no-units").string() + " --landmarks " + (dir / "head.npy").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.output, "head.obj: the mesh is")) << r.output;
  EXPECT_TRUE(contains(r.output, "--units cm")) << r.output;

  r = run_gvkit("facemap clean " + (dir / "head.obj").string() + " -o " + (dir / "out").string() +
                " --units cm --landmarks " + (dir / "head.npy").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json frame = first_frame(dir / "out");
  ASSERT_EQ(frame["ok"], true) << frame.dump();
  const auto& repair = frame["mesh_input"]["repair"];
  std::printf("repair: %s\n", repair["summary"].get<std::string>().c_str());
  const Injected& n = f.injected;
  EXPECT_EQ(repair["duplicate_faces"], n.duplicates);
  EXPECT_EQ(repair["non_manifold_edges"], n.fins);
  EXPECT_EQ(repair["non_manifold_faces"], n.fins);
  EXPECT_EQ(repair["flipped_faces"], n.flipped);
  EXPECT_EQ(repair["degenerate_faces"], n.zero_area);
  EXPECT_EQ(repair["non_finite_faces"], n.nan_faces);
  EXPECT_EQ(repair["components"], 1 + n.islands);
  EXPECT_EQ(repair["removed_component_faces"], 2 * n.islands);
  EXPECT_GE(repair["removed_vertices"].get<int>(), n.unreferenced + 4 * n.islands + n.fins);
  EXPECT_EQ(frame["mesh_input"]["landmarks"]["source"], "file");
  EXPECT_EQ(frame["mesh_input"]["file"]["mm_per_unit"], 10.0);
  const double error = check_face(dir / "out", f.landmarks_mm, f.injected.debris);
  std::printf("landmarks from the .npy: eyes and mouth %.2f mm from the truth\n", error);
  EXPECT_LT(error, 1.0);
}

TEST_F(CliFacemapRawMesh, BinaryPlyWith51TexturePixelLandmarks) {
  if (!fixture_) GTEST_SKIP() << "../shared/data is absent; this test needs it";
  const Fixture& f = *fixture_;
  TempDir dir;
  write_head(dir / "scan.ply", f.head.soup, 1.0);
  // iBUG points 17-67 as pixels of the texture image, one per row, comma separated.
  std::string text = "# x, y (texture pixels)\n";
  for (int i = 17; i < 68; ++i)
    text += std::to_string(f.head.landmark_pixels[i].x) + ", " +
            std::to_string(f.head.landmark_pixels[i].y) + "\n";
  ASSERT_TRUE(write_file_atomically(dir / "scan.landmarks.txt", text).is_ok());
  // Found beside the mesh (scan.landmarks.txt).
  auto r =
      run_gvkit("facemap clean " + (dir / "scan.ply").string() + " -o " + (dir / "out").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json frame = first_frame(dir / "out");
  ASSERT_EQ(frame["ok"], true) << frame.dump();
  EXPECT_EQ(frame["mesh_input"]["landmarks"]["points"], 51);
  EXPECT_EQ(frame["mesh_input"]["landmarks"]["dims"], 2);
  EXPECT_EQ(frame["mesh_input"]["file"]["textures"][0], "head.png");
  const double error = check_face(dir / "out", f.landmarks_mm, f.injected.debris);
  std::printf("landmarks from texture pixels: eyes and mouth %.2f mm from the truth\n", error);
  EXPECT_LT(error, 1.5);
  // The jaw was not given: absent in the output too, which facemap map takes.
  auto landmarks = read_face_landmarks(dir / "out" / "frame_000000.landmarks.json");
  ASSERT_TRUE(landmarks.is_ok()) << landmarks.status().message();
  EXPECT_TRUE(std::isnan(landmarks->points_mm[8][0]));
  r = run_gvkit("facemap map " + (dir / "out").string() + " -o " + (dir / "map").string() +
                " --size 48x48");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto stats = read_json(dir / "map" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["summary"]["mapped"], 1);
  EXPECT_EQ((*stats)["summary"]["flipped_total"], 0);
}

TEST_F(CliFacemapRawMesh, LandmarksDetectedOnTheTexturedRender) {
  if (!fixture_) GTEST_SKIP() << "../shared/data is absent; this test needs it";
  if (!fs::exists("/usr/share/dlib/shape_predictor_68_face_landmarks.dat"))
    GTEST_SKIP() << "dlib model absent (package libdlib-data)";
  const Fixture& f = *fixture_;
  TempDir dir;
  write_head(dir / "head.obj", f.head.soup, 1.0);
  auto r =
      run_gvkit("facemap clean " + (dir / "head.obj").string() + " -o " + (dir / "out").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json frame = first_frame(dir / "out");
  ASSERT_EQ(frame["ok"], true) << frame.dump();
  const auto& how = frame["mesh_input"]["landmarks"];
  EXPECT_EQ(how["source"], "detected");
  EXPECT_EQ(how["render"], "texture");
  const double error = check_face(dir / "out", f.landmarks_mm, f.injected.debris);
  std::printf("landmarks detected on the texture (%s view): eyes and mouth %.2f mm off\n",
              how["view"].get<std::string>().c_str(), error);
  EXPECT_LT(error, 6.0);
  // Without detection and without a landmark file the frame is refused with the reason.
  r = run_gvkit("facemap clean " + (dir / "head.obj").string() + " -o " + (dir / "off").string() +
                " --no-detect");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.output, "head.obj: no landmark file")) << r.output;
}

}  // namespace
}  // namespace gvkit
