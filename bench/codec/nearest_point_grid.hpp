#pragma once
// Exact nearest-point queries over a 3D point set in a uniform hash grid (bench only: matches
// the points a peer decodes, in the peer's own order, back to the pixels of a geometry image).
// Build O(n log n); a query visits cube shells of cells around its own cell (clipped to the
// points' box) until no unvisited cell can hold a nearer point, so it costs a few cells when the
// cell size is about the point spacing and the query lies near a point, as a decoded point does.

#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace gvkit::bench {

class NearestPointGrid {
 public:
  // points: finite positions (mm); cell_mm > 0 (contract), best about the point spacing.
  NearestPointGrid(std::vector<cv::Vec3f> points, double cell_mm);

  // Index into points of a point nearest to p (ties: the lower index); -1 when there are none.
  int64_t nearest(const cv::Vec3f& p) const;
  const std::vector<cv::Vec3f>& points() const { return points_; }

 private:
  struct Cell {
    int64_t x, y, z;
  };
  Cell cell_of(const cv::Vec3f& p) const;
  static uint64_t key(int64_t x, int64_t y, int64_t z);

  std::vector<cv::Vec3f> points_;
  std::vector<int32_t> order_;  // point indices sorted by cell key
  std::unordered_map<uint64_t, std::pair<int32_t, int32_t>> cells_;  // key -> range in order_
  cv::Vec3d origin_{0, 0, 0};
  double cell_mm_ = 1;
  Cell hi_cell_{0, 0, 0};  // the cell of the box's far corner (the near corner is cell 0, 0, 0)
};

}  // namespace gvkit::bench
