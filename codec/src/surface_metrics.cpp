#include "gvkit/codec/surface_metrics.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "gvkit/codec/point_triangle_distance.hpp"
#include "gvkit/core/cpu_features.hpp"

namespace gvkit::codec {
namespace {

using Vec3 = cv::Vec3d;

Vec3 cross(const Vec3& a, const Vec3& b) { return a.cross(b); }

// The triangles of an image's fixed grid triangulation: the quad with top-left pixel (x, y)
// splits along (x, y)-(x+1, y+1) when its four pixels are valid, and gives the one triangle of
// its three valid pixels when one is not. Triangles are triples of pixel indices (y * cols + x)
// into the image's coordinates, held as doubles; each quad has a bounding sphere for pruning.

class GridTriangles {
 public:
  GridTriangles(const cv::Mat& xyz_mm, const cv::Mat& valid)
      : cols_(std::max(0, xyz_mm.cols - 1)),
        first_(static_cast<size_t>(cols_) * std::max(0, xyz_mm.rows - 1) + 1, 0),
        sx_(first_.size() - 1, 0.0),
        sy_(sx_.size(), 0.0),
        sz_(sx_.size(), 0.0),
        sr_(sx_.size(), -1.0) {
    const int w = xyz_mm.cols, h = xyz_mm.rows;
    const size_t pixels = static_cast<size_t>(w) * h;
    x_.resize(pixels);
    y_.resize(pixels);
    z_.resize(pixels);
    for (int y = 0; y < h; ++y) {
      const cv::Vec3f* row = xyz_mm.ptr<cv::Vec3f>(y);
      for (int x = 0; x < w; ++x) {
        const size_t i = static_cast<size_t>(y) * w + x;
        x_[i] = row[x][0];
        y_[i] = row[x][1];
        z_[i] = row[x][2];
      }
    }
    const int rows = std::max(0, h - 1);
    for (auto* v : {&a_, &b_, &c_}) v->reserve(2 * sx_.size());
    for (int y = 0; y < rows; ++y) {
      const uint8_t* m0 = valid.ptr<uint8_t>(y);
      const uint8_t* m1 = valid.ptr<uint8_t>(y + 1);
      for (int x = 0; x < cols_; ++x) {
        const size_t quad = static_cast<size_t>(y) * cols_ + x;
        first_[quad] = static_cast<int32_t>(a_.size());
        const int32_t i00 = static_cast<int32_t>(static_cast<size_t>(y) * w + x), i10 = i00 + 1,
                      i01 = i00 + w, i11 = i01 + 1;
        const bool v00 = m0[x] != 0, v10 = m0[x + 1] != 0, v01 = m1[x] != 0, v11 = m1[x + 1] != 0;
        const int n = v00 + v10 + v01 + v11;
        if (n < 3) continue;
        // The quad's valid corners in the order 00, 10, 11, 01.
        int32_t c[4];
        int k = 0;
        if (v00) c[k++] = i00;
        if (v10) c[k++] = i10;
        if (v11) c[k++] = i11;
        if (v01) c[k++] = i01;
        if (n == 4) {
          add(i00, i10, i11);
          add(i00, i11, i01);
        } else {
          add(c[0], c[1], c[2]);
        }
        // A sphere around the corners holds their triangles; widened by a relative 1e-9 so
        // that rounding cannot prune a triangle that holds the nearest point.
        Vec3 centre(0, 0, 0);
        for (int j = 0; j < n; ++j) centre += vertex(c[j]);
        centre *= 1.0 / n;
        double r2 = 0;
        for (int j = 0; j < n; ++j)
          r2 = std::max(r2, (vertex(c[j]) - centre).dot(vertex(c[j]) - centre));
        sx_[quad] = centre[0];
        sy_[quad] = centre[1];
        sz_[quad] = centre[2];
        sr_[quad] = std::sqrt(r2) * (1 + 1e-9) + 1e-9;
      }
    }
    first_.back() = static_cast<int32_t>(a_.size());
  }

  int quad_columns() const { return cols_; }
  int quad_rows() const { return cols_ ? static_cast<int>((first_.size() - 1) / cols_) : 0; }
  VertexArrays vertices() const { return {x_.data(), y_.data(), z_.data()}; }
  Vec3 vertex(int32_t i) const { return Vec3(x_[i], y_[i], z_[i]); }
  // The triangles of quads (x0..x1, y): first() and count().
  int first(int x0, int y) const { return first_[static_cast<size_t>(y) * cols_ + x0]; }
  int count(int x0, int x1, int y) const {
    return first_[static_cast<size_t>(y) * cols_ + x1 + 1] - first(x0, y);
  }
  TriangleIndices triangles(int from = 0) const {
    return {a_.data() + from, b_.data() + from, c_.data() + from};
  }
  int32_t a(int i) const { return a_[i]; }
  int32_t b(int i) const { return b_[i]; }
  int32_t c(int i) const { return c_[i]; }
  // Spheres around the triangles of quads (x, y), (x + 1, y), ... (radius < 0: no triangle).
  SphereArrays quad_spheres(int x, int y) const {
    const size_t i = static_cast<size_t>(y) * cols_ + x;
    return {sx_.data() + i, sy_.data() + i, sz_.data() + i, sr_.data() + i};
  }

 private:
  void add(int32_t a, int32_t b, int32_t c) {
    a_.push_back(a);
    b_.push_back(b);
    c_.push_back(c);
  }

  int cols_;
  std::vector<int32_t> first_;      // per quad (row-major), its first triangle; one past the end
  std::vector<int32_t> a_, b_, c_;  // per triangle, its corners' vertex indices
  std::vector<double> sx_, sy_, sz_, sr_;  // per quad (row-major): sphere centre and radius
  std::vector<double> x_, y_, z_;          // per pixel
};

// Whether valid pixel (x, y) lies on the outline: a 4-neighbour outside the image or invalid.
bool on_outline(const cv::Mat& valid, int x, int y) {
  const auto ok = [&](int u, int v) {
    return u >= 0 && v >= 0 && u < valid.cols && v < valid.rows && valid.at<uint8_t>(v, u) != 0;
  };
  return !ok(x - 1, y) || !ok(x + 1, y) || !ok(x, y - 1) || !ok(x, y + 1);
}

// Directed vertex-to-surface distances from the valid pixels of `from` to the triangles of `to`
// within the window: max, max over outline pixels, and their sum and count into e; each pixel's
// distance into `map` (CV_32F) when given. A pixel's distance is the smallest of the distance to
// `to`'s vertex at the same pixel and the distances to the window's triangles: the triangles of
// the (up to) four quads around the pixel first, which bring the bound down to about the final
// distance, then those of the other quads whose spheres the bound does not exclude.
void directed_distances(const cv::Mat& from, const GridTriangles& to, const cv::Mat& valid,
                        int window, double& max_mm, SurfaceError& e, cv::Mat* map = nullptr) {
  const VertexArrays vertices = to.vertices();
  // Candidate triangles: at most 2 for each of (2 window)^2 quads.
  std::vector<int32_t> ca(8 * window * window), cb(ca.size()), cc(ca.size());
  int n = 0;
  // Adds the triangles of quads (qx0..qx1, qy) to the candidates.
  const auto take = [&](int qx0, int qx1, int qy) {
    for (int i = to.first(qx0, qy), end = i + to.count(qx0, qx1, qy); i < end; ++i, ++n) {
      ca[n] = to.a(i);
      cb[n] = to.b(i);
      cc[n] = to.c(i);
    }
  };
  const auto nearest = [&](const Vec3& p, double bound) {
    return n > 0 ? nearest_triangle_distance2(p, vertices, {ca.data(), cb.data(), cc.data()}, n,
                                              bound)
                 : bound;
  };
  for (int y = 0; y < from.rows; ++y)
    for (int x = 0; x < from.cols; ++x) {
      if (!valid.at<uint8_t>(y, x)) continue;
      const Vec3 p(from.at<cv::Vec3f>(y, x));
      // Upper bound first: the other surface's vertex at the same pixel (valid in both).
      const Vec3 same = to.vertex(y * from.cols + x);
      double best2 = (p - same).dot(p - same);
      const int qx0 = std::max(0, x - window),
                qx1 = std::min(to.quad_columns() - 1, x + window - 1);
      const int qy0 = std::max(0, y - window), qy1 = std::min(to.quad_rows() - 1, y + window - 1);
      // The (up to) four quads that have the pixel as a corner, their (up to) eight triangles in
      // one call.
      const int nx0 = std::max(qx0, x - 1), nx1 = std::min(qx1, x);
      const int ny0 = std::max(qy0, y - 1), ny1 = std::min(qy1, y);
      n = 0;
      if (nx0 <= nx1)
        for (int qy = ny0; qy <= ny1; ++qy) take(nx0, nx1, qy);
      best2 = nearest(p, best2);
      // A triangle can only come closer than `best` when p lies within radius + best of its
      // quad's centre.
      const double best = std::sqrt(best2);
      n = 0;
      // The quads around the pixel, already searched, as bits of a window row.
      const uint32_t near = nx0 <= nx1 ? ((2u << (nx1 - qx0)) - 1) & ~((1u << (nx0 - qx0)) - 1) : 0;
      for (int qy = qy0; qy <= qy1; ++qy) {
        uint32_t bits = spheres_within_reach(p, to.quad_spheres(qx0, qy), qx1 - qx0 + 1, best);
        if (qy >= ny0 && qy <= ny1) bits &= ~near;
        for (; bits; bits &= bits - 1) {
          const int qx = qx0 + std::countr_zero(bits);
          take(qx, qx, qy);
        }
      }
      best2 = nearest(p, best2);
      const double d = std::sqrt(best2);
      if (map) map->at<float>(y, x) = static_cast<float>(d);
      max_mm = std::max(max_mm, d);
      if (on_outline(valid, x, y)) e.outline_hausdorff_mm = std::max(e.outline_hausdorff_mm, d);
      e.distance_sum_mm += d;
      ++e.distance_samples;
    }
}

}  // namespace

Status SurfaceErrorOptions::check() const {
  if (window_px < 1 || window_px > 16)
    return invalid_argument("surface error window " + std::to_string(window_px) +
                            " px out of range (1..16)");
  if (!(normal_scale_px >= 0) || normal_scale_px > 8)
    return invalid_argument("normal scale " + std::to_string(normal_scale_px) +
                            " px out of range (0..8)");
  return Status::ok();
}

namespace {

// sum[x] += g * src[x] for x < w, the smoothing's one operation: in AVX2 where the processor has
// it, with the same product and sum per element (no fused multiply-add), so the same doubles.
void add_scaled_plain(double* sum, const double* src, double g, int w) {
  for (int x = 0; x < w; ++x) sum[x] += g * src[x];
}
#if defined(GVKIT_X86_SIMD)
GVKIT_TARGET_AVX2 void add_scaled_avx2(double* sum, const double* src, double g, int w) {
  const __m256d gv = _mm256_set1_pd(g);
  int x = 0;
  for (; x + 4 <= w; x += 4)
    _mm256_storeu_pd(sum + x, _mm256_add_pd(_mm256_loadu_pd(sum + x),
                                            _mm256_mul_pd(gv, _mm256_loadu_pd(src + x))));
  for (; x < w; ++x) sum[x] += g * src[x];
}
#endif

}  // namespace

cv::Mat smooth_positions(const cv::Mat& xyz_mm, const cv::Mat& valid, double sigma_px) {
  GVKIT_CHECK(xyz_mm.type() == CV_32FC3 && valid.type() == CV_8U && valid.size() == xyz_mm.size());
  if (!(sigma_px > 0)) return xyz_mm.clone();
  const int radius = static_cast<int>(std::ceil(3 * sigma_px));
  std::vector<double> kernel(2 * radius + 1);
  for (int k = -radius; k <= radius; ++k)
    kernel[k + radius] = std::exp(-0.5 * k * k / (sigma_px * sigma_px));
  const int w = xyz_mm.cols, h = xyz_mm.rows;
  // Weighted sums of the valid pixels, rows then columns, one channel at a time: the weights
  // first (their sums divide the others'), then x, y and z. An invalid pixel, and the zero
  // padding beyond the image, add +0 (the sums start at +0 and stay nonnegative zero or nonzero,
  // so adding +0 changes no bit), and every sum runs over its offsets from -radius up, the order
  // of a plain per-pixel loop.
  auto add_scaled = add_scaled_plain;
#if defined(GVKIT_X86_SIMD)
  if (gvkit::detail::cpu_has_avx2()) add_scaled = add_scaled_avx2;
#endif
  const int pw = w + 2 * radius;
  std::vector<double> padded_row(static_cast<size_t>(pw), 0.0);
  // Row sums of the channel, with radius zero rows above and below.
  std::vector<double> rows(static_cast<size_t>(w) * (h + 2 * radius), 0.0);
  std::vector<double> weight(static_cast<size_t>(w) * h), sums(static_cast<size_t>(w));
  cv::Mat out = xyz_mm.clone();
  for (const int c : {3, 0, 1, 2}) {
    for (int y = 0; y < h; ++y) {
      const cv::Vec3f* p = xyz_mm.ptr<cv::Vec3f>(y);
      const uint8_t* m = valid.ptr<uint8_t>(y);
      for (int x = 0; x < w; ++x)
        padded_row[static_cast<size_t>(x + radius)] = !m[x] ? 0.0 : (c == 3 ? 1.0 : p[x][c]);
      double* sum = &rows[static_cast<size_t>(y + radius) * w];
      std::fill(sum, sum + w, 0.0);
      for (int k = 0; k <= 2 * radius; ++k)
        add_scaled(sum, &padded_row[static_cast<size_t>(k)], kernel[static_cast<size_t>(k)], w);
    }
    for (int y = 0; y < h; ++y) {
      double* s = c == 3 ? &weight[static_cast<size_t>(y) * w] : sums.data();
      std::fill(s, s + w, 0.0);
      for (int k = 0; k <= 2 * radius; ++k)
        add_scaled(s, &rows[static_cast<size_t>(y + k) * w], kernel[static_cast<size_t>(k)], w);
      if (c == 3) continue;
      const uint8_t* m = valid.ptr<uint8_t>(y);
      const double* wt = &weight[static_cast<size_t>(y) * w];
      cv::Vec3f* o = out.ptr<cv::Vec3f>(y);
      for (int x = 0; x < w; ++x)
        if (m[x] && wt[x] > 0) o[x][c] = static_cast<float>(s[x] / wt[x]);
    }
  }
  return out;
}

cv::Mat surface_valid_pixels(const GeometryImage& reference, const GeometryImage& decoded) {
  GVKIT_CHECK(reference.xyz_mm.size() == decoded.xyz_mm.size() &&
              reference.xyz_mm.type() == CV_32FC3 && decoded.xyz_mm.type() == CV_32FC3 &&
              reference.domain_mask.size() == reference.xyz_mm.size() &&
              reference.domain_mask.type() == CV_8U);
  cv::Mat valid(reference.xyz_mm.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < valid.rows; ++y) {
    const cv::Vec3f* a = reference.xyz_mm.ptr<cv::Vec3f>(y);
    const cv::Vec3f* b = decoded.xyz_mm.ptr<cv::Vec3f>(y);
    const uint8_t* m = reference.domain_mask.ptr<uint8_t>(y);
    uint8_t* v = valid.ptr<uint8_t>(y);
    for (int x = 0; x < valid.cols; ++x) {
      bool finite = m[x] != 0;
      for (int k = 0; k < 3 && finite; ++k)
        finite = std::isfinite(a[x][k]) && std::isfinite(b[x][k]);
      v[x] = finite ? 255 : 0;
    }
  }
  return valid;
}

cv::Mat grid_normals(const cv::Mat& xyz_mm, const cv::Mat& valid) {
  GVKIT_CHECK(xyz_mm.type() == CV_32FC3 && valid.type() == CV_8U && valid.size() == xyz_mm.size());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cv::Mat normals(xyz_mm.size(), CV_32FC3, cv::Scalar(nan, nan, nan));
  const auto ok = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < xyz_mm.cols && y < xyz_mm.rows && valid.at<uint8_t>(y, x);
  };
  // Neighbours right, down, left, up: consecutive pairs span the four quadrants, each pair's
  // cross product facing the same side.
  const int dx[4] = {1, 0, -1, 0}, dy[4] = {0, 1, 0, -1};
  for (int y = 0; y < xyz_mm.rows; ++y)
    for (int x = 0; x < xyz_mm.cols; ++x) {
      if (!valid.at<uint8_t>(y, x)) continue;
      const Vec3 p(xyz_mm.at<cv::Vec3f>(y, x));
      Vec3 sum(0, 0, 0);
      for (int k = 0; k < 4; ++k) {
        const int k1 = (k + 1) % 4;
        if (!ok(x + dx[k], y + dy[k]) || !ok(x + dx[k1], y + dy[k1])) continue;
        const Vec3 e0 = Vec3(xyz_mm.at<cv::Vec3f>(y + dy[k], x + dx[k])) - p;
        const Vec3 e1 = Vec3(xyz_mm.at<cv::Vec3f>(y + dy[k1], x + dx[k1])) - p;
        sum += cross(e0, e1);
      }
      const double n = std::sqrt(sum.dot(sum));
      if (n > 0 && std::isfinite(n)) normals.at<cv::Vec3f>(y, x) = cv::Vec3f(sum / n);
    }
  return normals;
}

namespace {

// normal_error_deg over the valid pixels (surface_valid_pixels) already made.
cv::Mat normal_error_over(const GeometryImage& reference, const GeometryImage& decoded,
                          const cv::Mat& valid, double sigma) {
  const cv::Mat na = grid_normals(smooth_positions(reference.xyz_mm, valid, sigma), valid);
  const cv::Mat nb = grid_normals(smooth_positions(decoded.xyz_mm, valid, sigma), valid);
  cv::Mat angle(valid.size(), CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  for (int y = 0; y < valid.rows; ++y)
    for (int x = 0; x < valid.cols; ++x) {
      const Vec3 a(na.at<cv::Vec3f>(y, x)), b(nb.at<cv::Vec3f>(y, x));
      if (!std::isfinite(a[0]) || !std::isfinite(b[0])) continue;
      // atan2 of |a x b| and a . b: accurate at small angles, where acos is not.
      const Vec3 c = cross(a, b);
      angle.at<float>(y, x) =
          static_cast<float>(std::atan2(std::sqrt(c.dot(c)), a.dot(b)) * 180.0 / M_PI);
    }
  return angle;
}

}  // namespace

cv::Mat normal_error_deg(const GeometryImage& reference, const GeometryImage& decoded,
                         const SurfaceErrorOptions& options) {
  return normal_error_over(reference, decoded, surface_valid_pixels(reference, decoded),
                           options.normal_scale_px);
}

cv::Mat surface_distance_mm(const GeometryImage& reference, const GeometryImage& decoded,
                            const SurfaceErrorOptions& options) {
  const Status ok = options.check();
  GVKIT_CHECK(ok.is_ok(), ok.message());
  const cv::Mat valid = surface_valid_pixels(reference, decoded);
  cv::Mat map(valid.size(), CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  SurfaceError unused;
  double max_mm = 0;
  directed_distances(decoded.xyz_mm, GridTriangles(reference.xyz_mm, valid), valid,
                     options.window_px, max_mm, unused, &map);
  return map;
}

double SurfaceError::normal_mean_deg() const {
  return normal_pixels ? angle_sum_deg / static_cast<double>(normal_pixels) : 0.0;
}

double SurfaceError::normal_percentile_deg(double q) const {
  if (normal_pixels == 0 || angle_histogram.empty()) return 0.0;
  const double rank = std::clamp(q, 0.0, 1.0) * static_cast<double>(normal_pixels);
  double below = 0;
  for (int k = 0; k < kBins; ++k) {
    const double n = static_cast<double>(angle_histogram[k]);
    if (n > 0 && below + n >= rank)
      return std::min(normal_max_deg, (k + std::clamp((rank - below) / n, 0.0, 1.0)) * kBinDeg);
    below += n;
  }
  return normal_max_deg;
}

double SurfaceError::surface_mean_mm() const {
  return distance_samples ? distance_sum_mm / static_cast<double>(distance_samples) : 0.0;
}

SurfaceError surface_error(const GeometryImage& reference, const GeometryImage& decoded,
                           const SurfaceErrorOptions& options) {
  const Status ok = options.check();
  GVKIT_CHECK(ok.is_ok(), ok.message());
  SurfaceError e;
  const cv::Mat valid = surface_valid_pixels(reference, decoded);
  const cv::Mat angle = normal_error_over(reference, decoded, valid, options.normal_scale_px);
  e.angle_histogram.assign(SurfaceError::kBins, 0);
  for (int y = 0; y < angle.rows; ++y) {
    const float* a = angle.ptr<float>(y);
    for (int x = 0; x < angle.cols; ++x) {
      if (!std::isfinite(a[x])) continue;
      const int bin =
          std::clamp(static_cast<int>(a[x] / SurfaceError::kBinDeg), 0, SurfaceError::kBins - 1);
      ++e.angle_histogram[bin];
      e.angle_sum_deg += a[x];
      e.normal_max_deg = std::max(e.normal_max_deg, static_cast<double>(a[x]));
      ++e.normal_pixels;
    }
  }
  const GridTriangles reference_triangles(reference.xyz_mm, valid);
  const GridTriangles decoded_triangles(decoded.xyz_mm, valid);
  directed_distances(reference.xyz_mm, decoded_triangles, valid, options.window_px,
                     e.to_decoded_max_mm, e);
  directed_distances(decoded.xyz_mm, reference_triangles, valid, options.window_px,
                     e.to_reference_max_mm, e);
  e.hausdorff_mm = std::max(e.to_decoded_max_mm, e.to_reference_max_mm);
  return e;
}

void accumulate(SurfaceError& total, const SurfaceError& frame) {
  if (!frame.angle_histogram.empty()) {
    if (total.angle_histogram.empty()) total.angle_histogram.assign(SurfaceError::kBins, 0);
    for (int k = 0; k < SurfaceError::kBins; ++k)
      total.angle_histogram[k] += frame.angle_histogram[k];
  }
  total.angle_sum_deg += frame.angle_sum_deg;
  total.normal_max_deg = std::max(total.normal_max_deg, frame.normal_max_deg);
  total.normal_pixels += frame.normal_pixels;
  total.hausdorff_mm = std::max(total.hausdorff_mm, frame.hausdorff_mm);
  total.to_decoded_max_mm = std::max(total.to_decoded_max_mm, frame.to_decoded_max_mm);
  total.to_reference_max_mm = std::max(total.to_reference_max_mm, frame.to_reference_max_mm);
  total.outline_hausdorff_mm = std::max(total.outline_hausdorff_mm, frame.outline_hausdorff_mm);
  total.distance_sum_mm += frame.distance_sum_mm;
  total.distance_samples += frame.distance_samples;
}

}  // namespace gvkit::codec
