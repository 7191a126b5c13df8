#include "gvkit/facemap/block_matching.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "gvkit/core/cpu_features.hpp"

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

Status check_images(const GeometryImage& reference, const GeometryImage& current) {
  if (reference.size() != current.size() || reference.xyz_mm.type() != CV_32FC3 ||
      current.xyz_mm.type() != CV_32FC3 || reference.domain_mask.size() != reference.size() ||
      current.domain_mask.size() != current.size())
    return invalid_argument("block matching: geometry images of different size or type");
  return Status::ok();
}

// One block of the current frame: its rectangle and the displacement into the reference frame
// with the smallest total squared error (best = infinity when no displacement qualifies).
struct BlockMatch {
  cv::Rect block;
  double best = std::numeric_limits<double>::infinity();
  int dx = 0, dy = 0;
};

// The figures of block_matching_error, summed over the blocks.
struct Sums {
  std::array<double, 3> sse{};
  double zero_sse = 0, weighted_sse = 0, total_area = 0;
  long long count = 0;

  void add(const GeometryImage& reference, const GeometryImage& current, const BlockMatch& m) {
    const cv::Mat& ref = reference.xyz_mm;
    const cv::Mat& cur = current.xyz_mm;
    const cv::Mat& ref_mask = reference.domain_mask;
    const cv::Mat& cur_mask = current.domain_mask;
    const bool matched = std::isfinite(m.best);
    for (int y = m.block.y; y < m.block.y + m.block.height; ++y)
      for (int x = m.block.x; x < m.block.x + m.block.width; ++x) {
        if (!cur_mask.at<uint8_t>(y, x)) continue;
        const int ry = matched ? y + m.dy : y, rx = matched ? x + m.dx : x;
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

  BlockMatchingError result() const {
    BlockMatchingError out;
    if (count == 0) return out;
    for (int c = 0; c < 3; ++c) out.mse_mm2[c] = sse[c] / count;
    out.mean_mse_mm2 = (sse[0] + sse[1] + sse[2]) / (3.0 * count);
    out.zero_motion_mean_mse_mm2 = zero_sse / count;
    if (total_area > 0) out.area_weighted_mean_mse_mm2 = weighted_sse / (3.0 * total_area);
    return out;
  }
};

// Calls search(block) for every block of the current frame with a domain pixel and sums the
// figures of the displacements it finds.
template <typename Search>
BlockMatchingError match_blocks(const GeometryImage& reference, const GeometryImage& current,
                                const BlockMatchingOptions& options, Search&& search) {
  const int w = current.xyz_mm.cols, h = current.xyz_mm.rows, bs = options.block_size;
  Sums sums;
  for (int by = 0; by < h; by += bs)
    for (int bx = 0; bx < w; bx += bs) {
      BlockMatch m;
      m.block = cv::Rect(bx, by, std::min(bs, w - bx), std::min(bs, h - by));
      if (cv::countNonZero(current.domain_mask(m.block)) == 0) continue;
      search(m);
      sums.add(reference, current, m);
    }
  return sums.result();
}

#if defined(GVKIT_X86_SIMD)

// A mask as one bit per pixel, each row padded by a zero word so that a run of bits may be read
// from any position of a row.
class MaskBits {
 public:
  explicit MaskBits(const cv::Mat& mask)
      : words_(mask.cols / 64 + 2), bits_(static_cast<size_t>(mask.rows) * words_, 0) {
    for (int y = 0; y < mask.rows; ++y) {
      const uint8_t* m = mask.ptr<uint8_t>(y);
      uint64_t* row = bits_.data() + static_cast<size_t>(y) * words_;
      for (int x = 0; x < mask.cols; ++x)
        if (m[x]) row[x >> 6] |= uint64_t{1} << (x & 63);
    }
  }
  const uint64_t* row(int y) const { return bits_.data() + static_cast<size_t>(y) * words_; }

 private:
  int words_;
  std::vector<uint64_t> bits_;
};

// n (1..64) bits of row from bit pos on.
inline uint64_t bits_at(const uint64_t* row, int pos, int n) {
  const int word = pos >> 6, offset = pos & 63;
  uint64_t v = row[word] >> offset;
  if (offset != 0 && offset + n > 64) v |= row[word + 1] << (64 - offset);
  return n == 64 ? v : v & ((uint64_t{1} << n) - 1);
}

// True when every bit set in a[pa, pa + n) is also set in b[pb, pb + n).
inline bool covered(const uint64_t* a, int pa, const uint64_t* b, int pb, int n) {
  for (int k = 0; k < n; k += 64) {
    const int m = std::min(64, n - k);
    if (bits_at(a, pa + k, m) & ~bits_at(b, pb + k, m)) return false;
  }
  return true;
}

// One candidate displacement of a block: the rows of the block in the current frame and of the
// displaced block in the reference frame, and the block's rows of `keep`.
struct Candidate {
  const float* cur;
  size_t cur_step;  // floats
  const float* ref;
  size_t ref_step;
  const int32_t* keep;
  size_t keep_step;
};

GVKIT_TARGET_AVX2_FMA inline double lane_sum(__m256d v) {
  const __m128d pair = _mm_add_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1));
  return _mm_cvtsd_f64(_mm_add_sd(pair, _mm_unpackhi_pd(pair, pair)));
}

// Sum of the squares (in double) of the float differences cur - ref over `floats` floats of each
// of `rows` rows, those where keep is 0 left out (keep is 0 or all ones). Returns infinity as
// soon as the sum of the rows so far exceeds bound, or when covers(row) is false for a row.
template <typename Covers>
GVKIT_TARGET_AVX2_FMA double block_cost_avx2(const Candidate& c, int floats, int rows, double bound,
                                             Covers&& covers) {
  __m256d sum_low = _mm256_setzero_pd(), sum_high = _mm256_setzero_pd();
  double tail = 0;
  const int vector_floats = floats & ~7;
  for (int y = 0; y < rows; ++y) {
    if (!covers(y)) return std::numeric_limits<double>::infinity();
    const float* cur = c.cur + y * c.cur_step;
    const float* ref = c.ref + y * c.ref_step;
    const int32_t* keep = c.keep + y * c.keep_step;
    for (int i = 0; i < vector_floats; i += 8) {
      const __m256 d = _mm256_and_ps(
          _mm256_sub_ps(_mm256_loadu_ps(cur + i), _mm256_loadu_ps(ref + i)),
          _mm256_castsi256_ps(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(keep + i))));
      const __m256d low = _mm256_cvtps_pd(_mm256_castps256_ps128(d));
      const __m256d high = _mm256_cvtps_pd(_mm256_extractf128_ps(d, 1));
      sum_low = _mm256_fmadd_pd(low, low, sum_low);
      sum_high = _mm256_fmadd_pd(high, high, sum_high);
    }
    for (int i = vector_floats; i < floats; ++i)
      if (keep[i]) {
        const double d = cur[i] - ref[i];
        tail += d * d;
      }
    if (lane_sum(_mm256_add_pd(sum_low, sum_high)) + tail > bound)
      return std::numeric_limits<double>::infinity();
  }
  return lane_sum(_mm256_add_pd(sum_low, sum_high)) + tail;
}

BlockMatchingError block_matching_error_avx2(const GeometryImage& reference,
                                             const GeometryImage& current,
                                             const BlockMatchingOptions& options) {
  const int w = current.xyz_mm.cols, h = current.xyz_mm.rows, r = options.search_range;
  const MaskBits cur_bits(current.domain_mask), ref_bits(reference.domain_mask);
  // keep: all ones on the three floats of every pixel of the current frame's domain.
  std::vector<int32_t> keep(static_cast<size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y) {
    const uint8_t* m = current.domain_mask.ptr<uint8_t>(y);
    for (int x = 0; x < w; ++x)
      std::fill_n(keep.begin() + (static_cast<size_t>(y) * w + x) * 3, 3, m[x] ? -1 : 0);
  }
  const size_t cur_step = current.xyz_mm.step1(), ref_step = reference.xyz_mm.step1();
  cv::Point previous(0, 0);  // the displacement of the block before
  return match_blocks(reference, current, options, [&](BlockMatch& m) {
    const cv::Rect& b = m.block;
    // The cost of displacement (dx, dy), infinity when it leaves the frame, when the reference's
    // domain does not cover the block's, or when it exceeds bound.
    auto cost = [&](int dx, int dy, double bound) {
      if (b.y + dy < 0 || b.x + dx < 0 || b.y + dy + b.height > h || b.x + dx + b.width > w)
        return std::numeric_limits<double>::infinity();
      const Candidate c{current.xyz_mm.ptr<float>(b.y) + 3 * b.x,
                        cur_step,
                        reference.xyz_mm.ptr<float>(b.y + dy) + 3 * (b.x + dx),
                        ref_step,
                        keep.data() + (static_cast<size_t>(b.y) * w + b.x) * 3,
                        static_cast<size_t>(w) * 3};
      return block_cost_avx2(c, 3 * b.width, b.height, bound, [&](int y) {
        return covered(cur_bits.row(b.y + y), b.x, ref_bits.row(b.y + y + dy), b.x + dx, b.width);
      });
    };
    // The plain search keeps the first displacement in raster order with the smallest cost.
    // Costs of the displacement of the block before and of no motion, taken first, bound the
    // others' sums from the start; a later tie then goes to the earlier displacement in raster
    // order, so the choice is the plain search's.
    auto raster = [&](int dx, int dy) { return (dy + r) * (2 * r + 1) + (dx + r); };
    int best_index = std::numeric_limits<int>::max();
    auto consider = [&](int dx, int dy) {
      if (std::abs(dx) > r || std::abs(dy) > r) return;
      const double c = cost(dx, dy, m.best);
      if (c < m.best || (c == m.best && std::isfinite(c) && raster(dx, dy) < best_index))
        m.best = c, m.dx = dx, m.dy = dy, best_index = raster(dx, dy);
    };
    consider(previous.x, previous.y);
    consider(0, 0);
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) consider(dx, dy);
    if (std::isfinite(m.best)) previous = cv::Point(m.dx, m.dy);
  });
}

#endif

}  // namespace

Status BlockMatchingOptions::check() const {
  if (block_size < 1 || block_size > 256)
    return invalid_argument("block matching: block size must be in 1..256");
  if (search_range < 0 || search_range > 256)
    return invalid_argument("block matching: search range must be in 0..256");
  return Status::ok();
}

Result<BlockMatchingError> block_matching_error_reference(const GeometryImage& reference,
                                                          const GeometryImage& current,
                                                          const BlockMatchingOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  GVKIT_RETURN_IF_ERROR(check_images(reference, current));
  const int w = current.xyz_mm.cols, h = current.xyz_mm.rows, r = options.search_range;
  const cv::Mat& ref = reference.xyz_mm;
  const cv::Mat& cur = current.xyz_mm;
  const cv::Mat& ref_mask = reference.domain_mask;
  const cv::Mat& cur_mask = current.domain_mask;
  return match_blocks(reference, current, options, [&](BlockMatch& m) {
    const cv::Rect& b = m.block;
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) {
        if (b.y + dy < 0 || b.x + dx < 0 || b.y + dy + b.height > h || b.x + dx + b.width > w)
          continue;
        double cost = 0;
        bool ok = true;
        for (int y = b.y; y < b.y + b.height && ok && cost < m.best; ++y)
          for (int x = b.x; x < b.x + b.width; ++x) {
            if (!cur_mask.at<uint8_t>(y, x)) continue;
            if (!ref_mask.at<uint8_t>(y + dy, x + dx)) {
              ok = false;
              break;
            }
            const cv::Vec3f d = cur.at<cv::Vec3f>(y, x) - ref.at<cv::Vec3f>(y + dy, x + dx);
            cost += double(d[0]) * d[0] + double(d[1]) * d[1] + double(d[2]) * d[2];
          }
        if (ok && cost < m.best) m.best = cost, m.dx = dx, m.dy = dy;
      }
  });
}

Result<BlockMatchingError> block_matching_error(const GeometryImage& reference,
                                                const GeometryImage& current,
                                                const BlockMatchingOptions& options) {
#if defined(GVKIT_X86_SIMD)
  if (gvkit::detail::cpu_has_avx2()) {
    GVKIT_RETURN_IF_ERROR(options.check());
    GVKIT_RETURN_IF_ERROR(check_images(reference, current));
    return block_matching_error_avx2(reference, current, options);
  }
#endif
  return block_matching_error_reference(reference, current, options);
}

}  // namespace gvkit::facemap
