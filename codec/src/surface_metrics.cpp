#include "gvkit/codec/surface_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace gvkit::codec {
namespace {

using Vec3 = cv::Vec3d;

Vec3 cross(const Vec3& a, const Vec3& b) { return a.cross(b); }

// Closest point to p on triangle abc (Ericson, Real-Time Collision Detection 5.1.5): the squared
// distance.
double point_triangle_distance2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.dot(ap);
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.dot(bp);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const Vec3 q = a + ab * (d1 / (d1 - d3));
    return (p - q).dot(p - q);
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.dot(cp);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const Vec3 q = a + ac * (d2 / (d2 - d6));
    return (p - q).dot(p - q);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const Vec3 q = b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    return (p - q).dot(p - q);
  }
  const double denom = 1.0 / (va + vb + vc);
  if (!std::isfinite(denom)) {  // degenerate triangle: the nearest of its corners
    return std::min({ap.dot(ap), bp.dot(bp), cp.dot(cp)});
  }
  const Vec3 q = a + ab * (vb * denom) + ac * (vc * denom);
  return (p - q).dot(p - q);
}

// The triangles of an image's fixed grid triangulation: the quad with top-left pixel (x, y)
// splits along (x, y)-(x+1, y+1) when its four pixels are valid, and gives the one triangle of
// its three valid pixels when one is not. Each triangle, and each quad, with a bounding sphere
// for pruning.
struct Sphere {
  Vec3 centre;
  double radius = -1;  // < 0: empty (a quad without triangles)
};

struct Triangle {
  Vec3 a, b, c;
  Vec3 centre;
  double radius = 0;
};

class GridTriangles {
 public:
  GridTriangles(const cv::Mat& xyz_mm, const cv::Mat& valid)
      : cols_(std::max(0, xyz_mm.cols - 1)),
        first_(static_cast<size_t>(cols_) * std::max(0, xyz_mm.rows - 1) + 1, 0),
        quad_spheres_(first_.size() - 1) {
    const int rows = std::max(0, xyz_mm.rows - 1);
    triangles_.reserve(2 * quad_spheres_.size());
    const auto at = [&](int x, int y) { return Vec3(xyz_mm.at<cv::Vec3f>(y, x)); };
    const auto ok = [&](int x, int y) { return valid.at<uint8_t>(y, x) != 0; };
    for (int y = 0; y < rows; ++y)
      for (int x = 0; x < cols_; ++x) {
        first_[static_cast<size_t>(y) * cols_ + x] = static_cast<int32_t>(triangles_.size());
        const bool v00 = ok(x, y), v10 = ok(x + 1, y), v01 = ok(x, y + 1), v11 = ok(x + 1, y + 1);
        const int n = v00 + v10 + v01 + v11;
        if (n == 4) {
          add(at(x, y), at(x + 1, y), at(x + 1, y + 1));
          add(at(x, y), at(x + 1, y + 1), at(x, y + 1));
        } else if (n == 3) {
          std::vector<Vec3> corners;
          if (v00) corners.push_back(at(x, y));
          if (v10) corners.push_back(at(x + 1, y));
          if (v11) corners.push_back(at(x + 1, y + 1));
          if (v01) corners.push_back(at(x, y + 1));
          add(corners[0], corners[1], corners[2]);
        }
        Sphere& q = quad_spheres_[static_cast<size_t>(y) * cols_ + x];
        const Triangle* t0 = triangles_.data() + first_[static_cast<size_t>(y) * cols_ + x];
        const Triangle* t1 = triangles_.data() + triangles_.size();
        if (t0 == t1) continue;
        for (const Triangle* t = t0; t != t1; ++t) q.centre += t->centre;
        q.centre *= 1.0 / static_cast<double>(t1 - t0);
        for (const Triangle* t = t0; t != t1; ++t)
          q.radius = std::max(
              q.radius, std::sqrt((t->centre - q.centre).dot(t->centre - q.centre)) + t->radius);
      }
    first_.back() = static_cast<int32_t>(triangles_.size());
  }

  int quad_columns() const { return cols_; }
  int quad_rows() const { return cols_ ? static_cast<int>((first_.size() - 1) / cols_) : 0; }
  // The triangles of quad (x, y): [begin, end).
  const Triangle* begin(int x, int y) const {
    return triangles_.data() + first_[static_cast<size_t>(y) * cols_ + x];
  }
  const Triangle* end(int x, int y) const {
    return triangles_.data() + first_[static_cast<size_t>(y) * cols_ + x + 1];
  }
  // A sphere around every triangle of quad (x, y).
  const Sphere& quad_sphere(int x, int y) const {
    return quad_spheres_[static_cast<size_t>(y) * cols_ + x];
  }

 private:
  void add(const Vec3& a, const Vec3& b, const Vec3& c) {
    Triangle t{a, b, c, (a + b + c) / 3.0, 0};
    t.radius =
        std::sqrt(std::max({(a - t.centre).dot(a - t.centre), (b - t.centre).dot(b - t.centre),
                            (c - t.centre).dot(c - t.centre)}));
    triangles_.push_back(t);
  }

  int cols_;
  std::vector<int32_t> first_;  // per quad (row-major), its first triangle; one past the end
  std::vector<Triangle> triangles_;
  std::vector<Sphere> quad_spheres_;  // per quad (row-major)
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
// distance into `map` (CV_32F) when given.
void directed_distances(const cv::Mat& from, const cv::Mat& to_xyz, const GridTriangles& to,
                        const cv::Mat& valid, int window, double& max_mm, SurfaceError& e,
                        cv::Mat* map = nullptr) {
  for (int y = 0; y < from.rows; ++y)
    for (int x = 0; x < from.cols; ++x) {
      if (!valid.at<uint8_t>(y, x)) continue;
      const Vec3 p(from.at<cv::Vec3f>(y, x));
      // Upper bound first: the other surface's vertex at the same pixel (valid in both).
      const Vec3 same(to_xyz.at<cv::Vec3f>(y, x));
      double best2 = (p - same).dot(p - same);
      double best = std::sqrt(best2);
      const int qx0 = std::max(0, x - window),
                qx1 = std::min(to.quad_columns() - 1, x + window - 1);
      const int qy0 = std::max(0, y - window), qy1 = std::min(to.quad_rows() - 1, y + window - 1);
      // A triangle can only come closer than `best` when p lies within radius + best of its
      // centre: compared squared, so the square root is taken only when the bound improves.
      for (int qy = qy0; qy <= qy1; ++qy)
        for (int qx = qx0; qx <= qx1; ++qx) {
          const Sphere& q = to.quad_sphere(qx, qy);
          const Vec3 pq = p - q.centre;
          if (q.radius < 0 || pq.dot(pq) >= (q.radius + best) * (q.radius + best)) continue;
          for (const Triangle* t = to.begin(qx, qy); t != to.end(qx, qy); ++t) {
            const Vec3 pc = p - t->centre;
            const double reach = t->radius + best;
            if (pc.dot(pc) >= reach * reach) continue;
            const double d2 = point_triangle_distance2(p, t->a, t->b, t->c);
            if (d2 < best2) {
              best2 = d2;
              best = std::sqrt(d2);
            }
          }
        }
      const double d = best;
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

cv::Mat smooth_positions(const cv::Mat& xyz_mm, const cv::Mat& valid, double sigma_px) {
  GVKIT_CHECK(xyz_mm.type() == CV_32FC3 && valid.type() == CV_8U && valid.size() == xyz_mm.size());
  if (!(sigma_px > 0)) return xyz_mm.clone();
  const int radius = static_cast<int>(std::ceil(3 * sigma_px));
  std::vector<double> kernel(2 * radius + 1);
  for (int k = -radius; k <= radius; ++k)
    kernel[k + radius] = std::exp(-0.5 * k * k / (sigma_px * sigma_px));
  const int w = xyz_mm.cols, h = xyz_mm.rows;
  // Weighted sums (x, y, z, weight) of the valid pixels: rows, then columns.
  std::vector<cv::Vec4d> rows(static_cast<size_t>(w) * h), sums(rows.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      cv::Vec4d s(0, 0, 0, 0);
      for (int k = std::max(0, x - radius); k <= std::min(w - 1, x + radius); ++k) {
        if (!valid.at<uint8_t>(y, k)) continue;
        const cv::Vec3f& p = xyz_mm.at<cv::Vec3f>(y, k);
        const double g = kernel[k - x + radius];
        s += cv::Vec4d(g * p[0], g * p[1], g * p[2], g);
      }
      rows[static_cast<size_t>(y) * w + x] = s;
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      cv::Vec4d s(0, 0, 0, 0);
      for (int k = std::max(0, y - radius); k <= std::min(h - 1, y + radius); ++k)
        s += kernel[k - y + radius] * rows[static_cast<size_t>(k) * w + x];
      sums[static_cast<size_t>(y) * w + x] = s;
    }
  cv::Mat out = xyz_mm.clone();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const cv::Vec4d& s = sums[static_cast<size_t>(y) * w + x];
      if (valid.at<uint8_t>(y, x) && s[3] > 0)
        out.at<cv::Vec3f>(y, x) =
            cv::Vec3f(static_cast<float>(s[0] / s[3]), static_cast<float>(s[1] / s[3]),
                      static_cast<float>(s[2] / s[3]));
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

cv::Mat normal_error_deg(const GeometryImage& reference, const GeometryImage& decoded,
                         const SurfaceErrorOptions& options) {
  const cv::Mat valid = surface_valid_pixels(reference, decoded);
  const double sigma = options.normal_scale_px;
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

cv::Mat surface_distance_mm(const GeometryImage& reference, const GeometryImage& decoded,
                            const SurfaceErrorOptions& options) {
  const Status ok = options.check();
  GVKIT_CHECK(ok.is_ok(), ok.message());
  const cv::Mat valid = surface_valid_pixels(reference, decoded);
  cv::Mat map(valid.size(), CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  SurfaceError unused;
  double max_mm = 0;
  directed_distances(decoded.xyz_mm, reference.xyz_mm, GridTriangles(reference.xyz_mm, valid),
                     valid, options.window_px, max_mm, unused, &map);
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
  const cv::Mat angle = normal_error_deg(reference, decoded, options);
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
  const cv::Mat valid = surface_valid_pixels(reference, decoded);
  const GridTriangles reference_triangles(reference.xyz_mm, valid);
  const GridTriangles decoded_triangles(decoded.xyz_mm, valid);
  directed_distances(reference.xyz_mm, decoded.xyz_mm, decoded_triangles, valid, options.window_px,
                     e.to_decoded_max_mm, e);
  directed_distances(decoded.xyz_mm, reference.xyz_mm, reference_triangles, valid,
                     options.window_px, e.to_reference_max_mm, e);
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
