#include "gvkit/facemap/block_matching.hpp"

#include <cmath>
#include <limits>

namespace gvkit::facemap {
namespace {

// Surface area (mm^2) one pixel of image samples: |dxyz/dx x dxyz/dy| with forward differences,
// backward ones where the next pixel is outside the mask; 0 where neither neighbour is inside.
double pixel_area_mm2(const cv::Mat& xyz, const cv::Mat& mask, int x, int y) {
  auto difference = [&](int dx, int dy, cv::Vec3f* d) {
    for (int sign : {1, -1}) {
      const int nx = x + sign * dx, ny = y + sign * dy;
      if (nx < 0 || ny < 0 || nx >= xyz.cols || ny >= xyz.rows || !mask.at<uint8_t>(ny, nx))
        continue;
      *d = (xyz.at<cv::Vec3f>(ny, nx) - xyz.at<cv::Vec3f>(y, x)) * static_cast<float>(sign);
      return true;
    }
    return false;
  };
  cv::Vec3f du, dv;
  if (!difference(1, 0, &du) || !difference(0, 1, &dv)) return 0;
  return cv::norm(du.cross(dv));
}

}  // namespace

Status BlockMatchingOptions::check() const {
  if (block_size < 1 || block_size > 256)
    return invalid_argument("block matching: block size must be in 1..256");
  if (search_range < 0 || search_range > 256)
    return invalid_argument("block matching: search range must be in 0..256");
  return Status::ok();
}

Result<BlockMatchingError> block_matching_error(const GeometryImage& reference,
                                                const GeometryImage& current,
                                                const BlockMatchingOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  if (reference.size() != current.size() || reference.xyz_mm.type() != CV_32FC3 ||
      current.xyz_mm.type() != CV_32FC3 || reference.domain_mask.size() != reference.size() ||
      current.domain_mask.size() != current.size())
    return invalid_argument("block matching: geometry images of different size or type");
  const int w = current.xyz_mm.cols, h = current.xyz_mm.rows, bs = options.block_size,
            r = options.search_range;
  const cv::Mat& ref = reference.xyz_mm;
  const cv::Mat& cur = current.xyz_mm;
  const cv::Mat& ref_mask = reference.domain_mask;
  const cv::Mat& cur_mask = current.domain_mask;
  std::array<double, 3> sse{};
  double zero_sse = 0, weighted_sse = 0, total_area = 0;
  long long count = 0;
  for (int by = 0; by < h; by += bs)
    for (int bx = 0; bx < w; bx += bs) {
      const int bw = std::min(bs, w - bx), bh = std::min(bs, h - by);
      int valid = 0;
      for (int y = by; y < by + bh; ++y)
        for (int x = bx; x < bx + bw; ++x) valid += cur_mask.at<uint8_t>(y, x) != 0;
      if (valid == 0) continue;
      // The displacement with the smallest total squared error among those whose reference
      // block covers every domain pixel of the current block.
      double best = std::numeric_limits<double>::infinity();
      int best_dx = 0, best_dy = 0;
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          if (by + dy < 0 || bx + dx < 0 || by + dy + bh > h || bx + dx + bw > w) continue;
          double cost = 0;
          bool ok = true;
          for (int y = by; y < by + bh && ok && cost < best; ++y)
            for (int x = bx; x < bx + bw; ++x) {
              if (!cur_mask.at<uint8_t>(y, x)) continue;
              if (!ref_mask.at<uint8_t>(y + dy, x + dx)) {
                ok = false;
                break;
              }
              const cv::Vec3f d = cur.at<cv::Vec3f>(y, x) - ref.at<cv::Vec3f>(y + dy, x + dx);
              cost += double(d[0]) * d[0] + double(d[1]) * d[1] + double(d[2]) * d[2];
            }
          if (ok && cost < best) best = cost, best_dx = dx, best_dy = dy;
        }
      for (int y = by; y < by + bh; ++y)
        for (int x = bx; x < bx + bw; ++x) {
          if (!cur_mask.at<uint8_t>(y, x)) continue;
          const bool matched = std::isfinite(best);
          const int ry = matched ? y + best_dy : y, rx = matched ? x + best_dx : x;
          if (!ref_mask.at<uint8_t>(ry, rx)) continue;
          const cv::Vec3f d = cur.at<cv::Vec3f>(y, x) - ref.at<cv::Vec3f>(ry, rx);
          for (int c = 0; c < 3; ++c) sse[c] += double(d[c]) * d[c];
          const double area = pixel_area_mm2(cur, cur_mask, x, y);
          weighted_sse += area * (double(d[0]) * d[0] + double(d[1]) * d[1] + double(d[2]) * d[2]);
          total_area += area;
          if (ref_mask.at<uint8_t>(y, x)) {
            const cv::Vec3f z = cur.at<cv::Vec3f>(y, x) - ref.at<cv::Vec3f>(y, x);
            zero_sse += (double(z[0]) * z[0] + double(z[1]) * z[1] + double(z[2]) * z[2]) / 3.0;
          }
          ++count;
        }
    }
  BlockMatchingError out;
  if (count == 0) return out;
  for (int c = 0; c < 3; ++c) out.mse_mm2[c] = sse[c] / count;
  out.mean_mse_mm2 = (sse[0] + sse[1] + sse[2]) / (3.0 * count);
  out.zero_motion_mean_mse_mm2 = zero_sse / count;
  if (total_area > 0) out.area_weighted_mean_mse_mm2 = weighted_sse / (3.0 * total_area);
  return out;
}

}  // namespace gvkit::facemap
