// Carrying a cleaned face to another frame of the same vertex layout: exact under an affine
// motion (barycentric anchors), layout mismatches rejected naming the frame.
#include "gvkit/facemap/face_transfer.hpp"

#include <gtest/gtest.h>

namespace gvkit::facemap {
namespace {

// A wavy n x n grid (mm), its vertices moved by `move`.
template <typename Move>
Mesh grid(int n, Move move) {
  Mesh mesh;
  std::vector<Mesh::VertexHandle> v;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const cv::Vec3d p = move(cv::Vec3d(x * 2.0, y * 2.0, std::sin(x * 0.3) * 3.0));
      v.push_back(mesh.add_vertex(Mesh::Point(p[0], p[1], p[2])));
    }
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      mesh.add_face(v[y * n + x], v[y * n + x + 1], v[(y + 1) * n + x + 1]);
      mesh.add_face(v[y * n + x], v[(y + 1) * n + x + 1], v[(y + 1) * n + x]);
    }
  return mesh;
}

cv::Vec3d affine(const cv::Vec3d& p) {
  return cv::Vec3d(1.1 * p[0] + 0.2 * p[1] + 5, 0.9 * p[1] - 0.1 * p[2] - 3, p[2] + 0.05 * p[0]);
}

TEST(FaceTransfer, AnchorsFollowAnAffineMotionExactly) {
  const Mesh a = grid(12, [](const cv::Vec3d& p) { return p; });
  const Mesh b = grid(12, affine);
  // Points on the surface: midpoints of faces and of edges.
  std::vector<cv::Vec3d> points;
  for (auto f : a.faces()) {
    if (f.idx() % 7) continue;
    cv::Vec3d c(0, 0, 0);
    for (auto v : a.fv_range(f)) c += cv::Vec3d(a.point(v)[0], a.point(v)[1], a.point(v)[2]) / 3.0;
    points.push_back(c);
  }
  auto anchors = anchor_points(a, points);
  ASSERT_TRUE(anchors.is_ok()) << anchors.status().message();
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_LT(cv::norm((*anchors)[i].offset_mm), 1e-9);
    EXPECT_LT(cv::norm(evaluate_anchor(b, (*anchors)[i]) - affine(points[i])), 1e-9);
  }
}

TEST(FaceTransfer, CleanedFaceVerticesAndLandmarksAreCarried) {
  const Mesh input_a = grid(12, [](const cv::Vec3d& p) { return p; });
  const Mesh input_b = grid(12, affine);
  CleanedFace reference;
  // The "cleaned" face: the input's inner part (a sub-grid of the same surface), one landmark.
  reference.mesh = grid(6, [](const cv::Vec3d& p) {
    return cv::Vec3d(p[0] + 4.0, p[1] + 4.0, std::sin((p[0] + 4.0) / 2.0 * 0.3) * 3.0);
  });
  reference.landmarks.points_mm = {cv::Vec3f(10, 10, static_cast<float>(std::sin(1.5) * 3.0))};
  TransferStats stats;
  auto out = transfer_cleaned_face(reference, input_a, input_b, "frame_000001.ply", &stats);
  ASSERT_TRUE(out.is_ok()) << out.status().message();
  EXPECT_EQ(out->mesh.n_vertices(), reference.mesh.n_vertices());
  EXPECT_EQ(stats.off_surface_vertices, 0);
  for (auto v : out->mesh.vertices()) {
    const auto& p = reference.mesh.point(v);
    const auto& q = out->mesh.point(v);
    EXPECT_LT(cv::norm(cv::Vec3d(q[0], q[1], q[2]) - affine(cv::Vec3d(p[0], p[1], p[2]))), 1e-9);
  }
  ASSERT_EQ(out->landmarks.points_mm.size(), 1u);
  EXPECT_LT(cv::norm(cv::Vec3d(out->landmarks.points_mm[0]) -
                     affine(cv::Vec3d(reference.landmarks.points_mm[0]))),
            1e-4);
}

TEST(FaceTransfer, DifferentLayoutIsAnErrorNamingTheFrame) {
  const Mesh a = grid(8, [](const cv::Vec3d& p) { return p; });
  const Mesh b = grid(9, [](const cv::Vec3d& p) { return p; });
  CleanedFace reference;
  reference.mesh = a;
  auto out = transfer_cleaned_face(reference, a, b, "frame_000007.ply");
  ASSERT_FALSE(out.is_ok());
  EXPECT_NE(out.status().message().find("frame_000007.ply"), std::string::npos);
}

}  // namespace
}  // namespace gvkit::facemap
