#pragma once
// Point location among 2D triangles (a triangulation's image in a parameter plane): a uniform
// grid of bins, each listing the triangles whose bounding box overlaps it.

#include <array>
#include <vector>

#include <Eigen/Core>

namespace gvkit::facemap {

class TriangleLocator {
 public:
  struct Hit {
    int triangle = -1;
    std::array<double, 3> barycentric{};  // of the point in that triangle
  };

  // corners[3k + j] is corner j of triangle k. bins_per_side ~ sqrt(#triangles) / 2 when 0:
  // about four triangles per bin, so that a triangle's bounding box overlaps a few bins (about
  // eleven with one triangle per bin on a 250K-vertex face's flow coordinates, where building
  // the bins took twice as long).
  explicit TriangleLocator(std::vector<Eigen::Vector2d> corners, int bins_per_side = 0);

  // The triangle containing p (barycentrics >= -tolerance); among several, the one whose
  // smallest barycentric is largest. triangle = -1 when none.
  Hit locate(const Eigen::Vector2d& p, double tolerance = 1e-9) const;
  // p's barycentrics in triangle k, computed as locate does (triangle = -1 when k is degenerate):
  // a cheap first test where consecutive queries tend to fall into the same triangle.
  Hit in_triangle(int k, const Eigen::Vector2d& p) const;
  int n_triangles() const { return static_cast<int>(corners_.size() / 3); }

 private:
  std::vector<Eigen::Vector2d> corners_;
  Eigen::Vector2d lo_, hi_;
  int nx_ = 1, ny_ = 1;
  std::vector<int> bin_start_, bin_items_;
};

}  // namespace gvkit::facemap
