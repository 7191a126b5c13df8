#include "gvkit/facemap/synthetic_head_mesh.hpp"

#include <algorithm>
#include <cmath>

#include "gvkit/facemap/mesh_texture.hpp"
#include "gvkit/facemap/synthetic_face_scan.hpp"
#include "triangle_raster.hpp"

namespace gvkit::facemap {

Status SyntheticHeadOptions::check() const {
  if (texture_px < 16 || texture_px > 8192)
    return invalid_argument("synthetic head: texture size must be in 16..8192 px");
  if (cv::norm(light) < 1e-9) return invalid_argument("synthetic head: light direction is zero");
  return Status::ok();
}

SyntheticHead synthetic_head_mesh(const IctFaceModel& model,
                                  const std::vector<cv::Vec3d>& positions_mm,
                                  const SyntheticHeadOptions& options) {
  GVKIT_CHECK(options.check().is_ok(), "synthetic_head_mesh: bad options");
  constexpr int kKept = 14062;  // face, head and neck, mouth socket, eye sockets
  SyntheticHead out;
  TriangleSoup& soup = out.soup;
  const std::vector<double> albedo = ict_vertex_albedo(model, positions_mm);
  out.point_of_vertex.assign(positions_mm.size(), -1);
  for (int v = 0; v < kKept && v < static_cast<int>(positions_mm.size()); ++v) {
    out.point_of_vertex[v] = static_cast<int>(soup.points.size());
    const auto& p = positions_mm[v];
    soup.points.emplace_back(p[0], p[1], p[2]);
    const auto a = static_cast<float>(albedo[v]);
    soup.colors.emplace_back(a, a, a, 1.0f);
  }
  // Texture coordinates: both UV tiles side by side in one image.
  auto uv_of = [&](int texcoord) {
    const cv::Vec2f& t = model.texcoords()[texcoord];
    return cv::Vec2f(t[0] / 2.0f, t[1]);
  };
  for (const auto& polygon : model.polygons()) {
    if (!std::all_of(polygon.begin(), polygon.end(),
                     [](const IctFaceModel::Corner& c) { return c.vertex < kKept; }))
      continue;
    ++soup.polygons;
    const IctRegion region = IctFaceModel::region_of(polygon[0].vertex);
    const bool textured =
        (region == IctRegion::kFace || region == IctRegion::kHeadAndNeck) &&
        std::all_of(polygon.begin(), polygon.end(), [](const auto& c) { return c.texcoord >= 0; });
    auto add = [&](int a, int b, int c) {
      soup.triangles.push_back({out.point_of_vertex[polygon[a].vertex],
                                out.point_of_vertex[polygon[b].vertex],
                                out.point_of_vertex[polygon[c].vertex]});
      soup.triangle_texture.push_back(textured ? 0 : -1);
      if (textured)
        soup.corner_uv.push_back(
            {uv_of(polygon[a].texcoord), uv_of(polygon[b].texcoord), uv_of(polygon[c].texcoord)});
      else
        soup.corner_uv.push_back({});
    };
    if (polygon.size() == 4) {
      ++soup.split_polygons;
      const auto& p = positions_mm;
      if (cv::norm(p[polygon[0].vertex] - p[polygon[2].vertex]) <=
          cv::norm(p[polygon[1].vertex] - p[polygon[3].vertex])) {
        add(0, 1, 2);
        add(0, 2, 3);
      } else {
        add(0, 1, 3);
        add(1, 2, 3);
      }
    } else {
      if (polygon.size() > 3) ++soup.split_polygons;
      for (size_t k = 1; k + 1 < polygon.size(); ++k)
        add(0, static_cast<int>(k), static_cast<int>(k + 1));
    }
  }

  // Smooth shading: area-weighted vertex normals.
  std::vector<cv::Vec3d> normal(soup.points.size(), cv::Vec3d(0, 0, 0));
  auto point = [&](int i) {
    const auto& p = soup.points[i];
    return cv::Vec3d(p[0], p[1], p[2]);
  };
  for (const auto& t : soup.triangles) {
    const cv::Vec3d n = (point(t[1]) - point(t[0])).cross(point(t[2]) - point(t[0]));
    for (int i : t) normal[i] += n;
  }
  const cv::Vec3d light = options.light / cv::norm(options.light);
  std::vector<double> shaded(soup.points.size());
  for (size_t i = 0; i < soup.points.size(); ++i) {
    const double len = cv::norm(normal[i]);
    const double lambert = len > 0 ? std::max(0.0, normal[i].dot(light) / len) : 0.0;
    shaded[i] = soup.colors[i][0] * (0.3 + 0.7 * lambert);
  }

  // Bake.
  const int rows = options.texture_px, cols = 2 * rows;
  cv::Mat image(rows, cols, CV_32F, cv::Scalar(0.0f));
  cv::Mat painted(rows, cols, CV_8U, cv::Scalar(0));
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    if (soup.triangle_texture[t] < 0) continue;
    cv::Vec2d px[3];
    for (int k = 0; k < 3; ++k) px[k] = texture_pixel(image, soup.corner_uv[t][k]);
    const auto& tri = soup.triangles[t];
    rasterize_triangle(px, cols, rows, [&](int x, int y, const double(&w)[3]) {
      image.at<float>(y, x) =
          static_cast<float>(w[0] * shaded[tri[0]] + w[1] * shaded[tri[1]] + w[2] * shaded[tri[2]]);
      painted.at<uint8_t>(y, x) = 255;
    });
  }
  // Grow the charts by a few pixels, so that sampling at their edges never reads the background.
  for (int round = 0; round < 3; ++round) {
    cv::Mat grown = image.clone(), grown_painted = painted.clone();
    for (int y = 0; y < rows; ++y)
      for (int x = 0; x < cols; ++x) {
        if (painted.at<uint8_t>(y, x)) continue;
        double sum = 0;
        int count = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int yy = y + dy, xx = x + dx;
            if (yy < 0 || yy >= rows || xx < 0 || xx >= cols || !painted.at<uint8_t>(yy, xx))
              continue;
            sum += image.at<float>(yy, xx);
            ++count;
          }
        if (count == 0) continue;
        grown.at<float>(y, x) = static_cast<float>(sum / count);
        grown_painted.at<uint8_t>(y, x) = 255;
      }
    image = grown;
    painted = grown_painted;
  }
  cv::Mat grey, bgr;
  image.convertTo(grey, CV_8U, 255.0);
  cv::Mat channels[3] = {grey, grey, grey};
  cv::merge(channels, 3, bgr);
  soup.textures = {bgr};
  soup.texture_paths = {"head.png"};

  // Landmark pixels: the face-tile texture coordinate of each landmark vertex.
  const auto& lm = model.landmark_vertices();
  out.landmark_pixels.assign(lm.size(), cv::Point2f(NAN, NAN));
  for (const auto& polygon : model.polygons())
    for (const auto& c : polygon) {
      if (c.texcoord < 0 || model.texcoords()[c.texcoord][0] > 1.0f) continue;
      for (size_t i = 0; i < lm.size(); ++i)
        if (lm[i] == c.vertex) {
          const cv::Vec2d p = texture_pixel(bgr, uv_of(c.texcoord));
          out.landmark_pixels[i] = cv::Point2f(static_cast<float>(p[0]), static_cast<float>(p[1]));
        }
    }
  return out;
}

}  // namespace gvkit::facemap
