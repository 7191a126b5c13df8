// Mesh from a synthetic range scan: counts, orientation, no triangle across a depth jump.
#include "gvkit/facemap/mesh_from_scan.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "gvkit/core/mesh_topology.hpp"

namespace gvkit::facemap {
namespace {

// A plane at z = 600 mm (pinhole, 1 mm pixel footprint at that depth) with a 16x16 px block
// raised to z = 550 mm in the middle, and a 4x4 px invalid hole elsewhere.
RangeScan stepped_scan(int n) {
  RangeScan scan;
  scan.xyz_mm = cv::Mat(n, n, CV_32FC3);
  scan.texture = cv::Mat(n, n, CV_32F);
  scan.valid = cv::Mat(n, n, CV_8U, cv::Scalar(255));
  scan.quality = cv::Mat(n, n, CV_32F, cv::Scalar(1.0f));
  scan.index = 7;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const bool block = x >= 24 && x < 40 && y >= 24 && y < 40;
      const bool hole = x >= 5 && x < 9 && y >= 5 && y < 9;
      const float z = block ? 550.0f : 600.0f;
      scan.xyz_mm.at<cv::Vec3f>(y, x) = {(x - n / 2) * z / 600.0f, (y - n / 2) * z / 600.0f, z};
      scan.texture.at<float>(y, x) = static_cast<float>(x) / n;
      if (hole) {
        scan.valid.at<uint8_t>(y, x) = 0;
        scan.xyz_mm.at<cv::Vec3f>(y, x) = {nan, nan, nan};
      }
    }
  return scan;
}

TEST(MeshFromScan, SkipsDepthJumpsAndKeepsTheLargestComponent) {
  const int n = 64;
  const RangeScan scan = stepped_scan(n);
  auto result = mesh_from_scan(scan);
  ASSERT_TRUE(result.is_ok()) << result.status().message();
  const ScanMesh& s = *result;
  EXPECT_NEAR(s.footprint_per_depth, 1.0 / 600.0, 1e-6);
  // The plane without block and hole: 64^2 - 256 - 16 pixels. Quads: 63^2 minus the 17^2
  // touching the block and the 5^2 touching the hole, two triangles each; plus one triangle in
  // each corner quad with three plane pixels (4 at the hole, 4 at the block).
  EXPECT_EQ(static_cast<int>(s.mesh.n_vertices()), n * n - 256 - 16);
  EXPECT_EQ(static_cast<int>(s.mesh.n_faces()), 2 * (63 * 63 - 17 * 17 - 5 * 5) + 8);
  EXPECT_EQ(s.repair.components, 2);
  // No edge across the 50 mm jump, nothing from the block.
  for (auto e : s.mesh.edges()) EXPECT_LT(s.mesh.calc_edge_length(e), 2.0);
  for (auto v : s.mesh.vertices()) EXPECT_NEAR(s.mesh.point(v)[2], 600.0, 1e-4);
  // Normals towards the camera, colours = texture, pixel maps consistent.
  Mesh mesh = s.mesh;
  mesh.request_face_normals();
  mesh.update_face_normals();
  for (auto f : mesh.faces()) EXPECT_LT(mesh.normal(f)[2], -0.99);
  for (auto v : s.mesh.vertices()) {
    const cv::Point px = s.vertex_pixel[v.idx()];
    EXPECT_EQ(s.vertex_of_pixel.at<int>(px), v.idx());
    EXPECT_FLOAT_EQ(s.mesh.color(v)[0], scan.texture.at<float>(px));
  }
  const MeshTopology topology = mesh_topology(s.mesh);
  EXPECT_EQ(topology.components, 1);
  EXPECT_EQ(topology.boundary_loops, 3);  // rim, block, hole
}

// Noisy scans lose pixels in speckles: where two gaps meet only diagonally, or a gap touches
// the rim at a pixel, a vertex has two open fans. The scan mesh keeps each such vertex's largest
// fan, so every boundary loop is a simple polygon (hole filling closes each with a disk).
TEST(MeshFromScan, OpensBoundaryPinches) {
  const int n = 48;
  RangeScan scan = stepped_scan(n);
  cv::RNG rng(5);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      if (rng.uniform(0.0, 1.0) < 0.12) {
        scan.valid.at<uint8_t>(y, x) = 0;
        scan.xyz_mm.at<cv::Vec3f>(y, x) = {nan, nan, nan};
      }
  auto result = mesh_from_scan(scan);
  ASSERT_TRUE(result.is_ok()) << result.status().message();
  const ScanMesh& s = *result;
  EXPECT_GT(s.repair.pinch_faces, 0);
  EXPECT_NE(s.repair.summary().find("boundary pinches"), std::string::npos);
  std::vector<int> open_fans(s.mesh.n_vertices(), 0);
  for (auto h : s.mesh.halfedges())
    if (s.mesh.is_boundary(h)) ++open_fans[s.mesh.from_vertex_handle(h).idx()];
  for (int f : open_fans) EXPECT_LE(f, 1);
  // Still a single planar piece with holes: genus 0 now that no vertex is counted for two.
  const MeshTopology topology = mesh_topology(s.mesh);
  EXPECT_EQ(topology.components, 1);
  EXPECT_EQ(topology.genus, 0);
  for (auto v : s.mesh.vertices())
    EXPECT_EQ(s.vertex_of_pixel.at<int>(s.vertex_pixel[v.idx()]), v.idx());
}

TEST(MeshFromScan, EmptyScanIsAnErrorNamingTheFrame) {
  RangeScan scan = stepped_scan(16);
  scan.valid.setTo(0);
  scan.xyz_mm.setTo(cv::Scalar::all(std::numeric_limits<float>::quiet_NaN()));
  auto result = mesh_from_scan(scan);
  ASSERT_FALSE(result.is_ok());
  EXPECT_NE(result.status().message().find("frame 7"), std::string::npos)
      << result.status().message();
}

TEST(MeshFromScan, OptionsAreChecked) {
  MeshFromScanOptions options;
  options.max_edge_factor = 0.5;
  EXPECT_FALSE(options.check().is_ok());
}

}  // namespace
}  // namespace gvkit::facemap
