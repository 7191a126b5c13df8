#include "gvkit/facemap/mesh_texture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace gvkit::facemap {

cv::Vec2d texture_pixel(const cv::Mat& image, const cv::Vec2f& uv) {
  return {uv[0] * image.cols - 0.5, (1.0 - uv[1]) * image.rows - 0.5};
}

cv::Vec2f texture_uv(const cv::Mat& image, const cv::Point2f& pixel) {
  return {static_cast<float>((pixel.x + 0.5) / image.cols),
          static_cast<float>(1.0 - (pixel.y + 0.5) / image.rows)};
}

namespace {

cv::Vec3f sample_bgr(const cv::Mat& image, const cv::Vec2f& uv) {
  if (!std::isfinite(uv[0]) || !std::isfinite(uv[1])) return {0.5f, 0.5f, 0.5f};
  const cv::Vec2d p = texture_pixel(image, uv);
  const double x = std::clamp(p[0], 0.0, image.cols - 1.0),
               y = std::clamp(p[1], 0.0, image.rows - 1.0);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const int x1 = std::min(x0 + 1, image.cols - 1), y1 = std::min(y0 + 1, image.rows - 1);
  const double fx = x - x0, fy = y - y0;
  auto at = [&](int yy, int xx) { return cv::Vec3d(image.at<cv::Vec3b>(yy, xx)) / 255.0; };
  const cv::Vec3d c = (1 - fy) * ((1 - fx) * at(y0, x0) + fx * at(y0, x1)) +
                      fy * ((1 - fx) * at(y1, x0) + fx * at(y1, x1));
  return cv::Vec3f(c);
}

// Barycentric weights of p in triangle (a, b, c); false for a degenerate triangle.
bool barycentric(const cv::Vec2d& p, const cv::Vec2d& a, const cv::Vec2d& b, const cv::Vec2d& c,
                 double w[3]) {
  const double area = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
  if (std::abs(area) < 1e-12) return false;
  w[1] = ((p[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (p[1] - a[1])) / area;
  w[2] = ((b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1])) / area;
  w[0] = 1.0 - w[1] - w[2];
  return true;
}

// Distance from p to segment ab.
double segment_distance(const cv::Vec2d& p, const cv::Vec2d& a, const cv::Vec2d& b) {
  const cv::Vec2d ab = b - a;
  const double len2 = ab.dot(ab);
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return cv::norm(p - (a + t * ab));
}

}  // namespace

float sample_texture_grey(const cv::Mat& image, const cv::Vec2f& uv) {
  const cv::Vec3f c = sample_bgr(image, uv);  // B, G, R
  return 0.114f * c[0] + 0.587f * c[1] + 0.299f * c[2];
}

void colour_vertices_from_texture(const MeshTexture& texture, Mesh* mesh) {
  GVKIT_CHECK(texture.face_image.size() == mesh->n_faces(), "one texture entry per face");
  const bool had = mesh->has_vertex_colors();
  mesh->request_vertex_colors();
  std::vector<cv::Vec3d> sum(mesh->n_vertices(), cv::Vec3d(0, 0, 0));
  std::vector<int> count(mesh->n_vertices(), 0);
  for (auto f : mesh->faces()) {
    const int image = texture.face_image[f.idx()];
    if (image < 0) continue;
    int k = 0;
    for (auto v : mesh->fv_range(f)) {
      sum[v.idx()] += cv::Vec3d(sample_bgr(texture.images[image], texture.face_uv[f.idx()][k++]));
      ++count[v.idx()];
    }
  }
  for (auto v : mesh->vertices()) {
    if (count[v.idx()] == 0) {
      if (!had) mesh->set_color(v, Mesh::Color(0.5f, 0.5f, 0.5f, 1.0f));
      continue;
    }
    const cv::Vec3d c = sum[v.idx()] / count[v.idx()];
    mesh->set_color(v, Mesh::Color(static_cast<float>(c[2]), static_cast<float>(c[1]),
                                   static_cast<float>(c[0]), 1.0f));
  }
}

Status TexturePointOptions::check() const {
  if (!(max_gap_px >= 0 && max_gap_px <= 100))
    return invalid_argument("texture points: max gap must be in [0, 100] px");
  if (!(max_spread_mm > 0)) return invalid_argument("texture points: max spread must be > 0 mm");
  return Status::ok();
}

Result<std::vector<cv::Vec3d>> surface_points_of_texture_pixels(
    const Mesh& mesh, const MeshTexture& texture, int image, const std::vector<cv::Point2f>& pixels,
    const std::string& name, const TexturePointOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  if (texture.empty() || image < 0 || image >= static_cast<int>(texture.images.size()))
    return failed_precondition(name + ": the mesh has no texture image for pixel landmarks");
  const cv::Mat& img = texture.images[image];
  // Every textured face's corners in pixels and in space.
  struct Face {
    cv::Vec2d px[3];
    cv::Vec3d xyz[3];
  };
  std::vector<Face> faces;
  for (auto f : mesh.faces()) {
    if (texture.face_image[f.idx()] != image) continue;
    Face face;
    int k = 0;
    for (auto v : mesh.fv_range(f)) {
      face.px[k] = texture_pixel(img, texture.face_uv[f.idx()][k]);
      const auto& p = mesh.point(v);
      face.xyz[k++] = cv::Vec3d(p[0], p[1], p[2]);
    }
    faces.push_back(face);
  }
  std::vector<cv::Vec3d> out;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const cv::Vec2d p(pixels[i].x, pixels[i].y);
    if (!std::isfinite(p[0]) || !std::isfinite(p[1])) {  // an absent point stays absent
      out.emplace_back(NAN, NAN, NAN);
      continue;
    }
    std::vector<cv::Vec3d> hits;
    double best_gap = std::numeric_limits<double>::infinity();
    cv::Vec3d nearest(0, 0, 0);
    for (const Face& face : faces) {
      double w[3];
      if (!barycentric(p, face.px[0], face.px[1], face.px[2], w)) continue;
      const double eps = -1e-9;
      if (w[0] >= eps && w[1] >= eps && w[2] >= eps) {
        hits.push_back(w[0] * face.xyz[0] + w[1] * face.xyz[1] + w[2] * face.xyz[2]);
        continue;
      }
      if (!hits.empty()) continue;
      // Outside: the distance to the face's outline; the point at the clamped weights.
      double gap = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 3; ++k)
        gap = std::min(gap, segment_distance(p, face.px[k], face.px[(k + 1) % 3]));
      if (gap < best_gap) {
        best_gap = gap;
        double sum = 0;
        for (double& x : w) sum += (x = std::max(0.0, x));
        nearest = (w[0] * face.xyz[0] + w[1] * face.xyz[1] + w[2] * face.xyz[2]) / sum;
      }
    }
    char where[96];
    std::snprintf(where, sizeof where, "point %zu at (%.1f, %.1f) px of the texture", i, p[0],
                  p[1]);
    if (hits.empty()) {
      if (!(best_gap <= options.max_gap_px))
        return failed_precondition(name + ": " + where + " lies on no textured face");
      out.push_back(nearest);
      continue;
    }
    double spread = 0;
    cv::Vec3d mean(0, 0, 0);
    for (const auto& a : hits) {
      mean += a / static_cast<double>(hits.size());
      for (const auto& b : hits) spread = std::max(spread, cv::norm(a - b));
    }
    if (spread > options.max_spread_mm)
      return failed_precondition(name + ": " + where + " lies on " + std::to_string(hits.size()) +
                                 " faces " + std::to_string(static_cast<int>(std::lround(spread))) +
                                 " mm apart (overlapping texture charts): ambiguous; give 3-D "
                                 "points instead");
    out.push_back(mean);
  }
  return out;
}

}  // namespace gvkit::facemap
