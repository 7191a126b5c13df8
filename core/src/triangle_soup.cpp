#include "gvkit/core/triangle_soup.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <opencv2/imgproc.hpp>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/file_extension.hpp"
#include "gvkit/core/image_io.hpp"
#include "triangle_soup_readers.hpp"

namespace gvkit {
namespace fs = std::filesystem;
namespace {

double squared_length(const Mesh::Point& a, const Mesh::Point& b) { return (a - b).sqrnorm(); }

// Polygons into triangles: a quad along its shorter diagonal, larger polygons as a fan from their
// first corner. Polygons of fewer than 3 corners are skipped (counted in a note); corners
// referring to a point the file lacks fail naming the face.
Status triangulate(const fs::path& path, const detail::SoupPolygons& polygons, TriangleSoup* soup) {
  const int n_points = static_cast<int>(soup->points.size());
  const bool with_uv =
      std::any_of(polygons.texture.begin(), polygons.texture.end(), [](int t) { return t >= 0; });
  int skipped = 0;
  for (int k = 0; k < polygons.size(); ++k) {
    const int first = polygons.start[k], count = polygons.start[k + 1] - first;
    for (int c = first; c < first + count; ++c) {
      const int p = polygons.corner_point[c];
      if (p < 0 || p >= n_points)
        return corrupt_data(path.string() + ": face " + std::to_string(k) + " refers to point " +
                            std::to_string(p) + ", the file has " + std::to_string(n_points));
    }
    if (count < 3) {
      ++skipped;
      continue;
    }
    if (count > 3) ++soup->split_polygons;
    auto add = [&](int a, int b, int c) {
      soup->triangles.push_back({polygons.corner_point[first + a], polygons.corner_point[first + b],
                                 polygons.corner_point[first + c]});
      if (!with_uv) return;
      const int texture = polygons.texture[k];
      soup->triangle_texture.push_back(texture);
      if (texture < 0)
        soup->corner_uv.push_back({});
      else
        soup->corner_uv.push_back({polygons.corner_uv[first + a], polygons.corner_uv[first + b],
                                   polygons.corner_uv[first + c]});
    };
    if (count == 4) {
      const auto& q = polygons.corner_point;
      const auto& pts = soup->points;
      const double d02 = squared_length(pts[q[first]], pts[q[first + 2]]);
      const double d13 = squared_length(pts[q[first + 1]], pts[q[first + 3]]);
      if (!(d13 < d02)) {
        add(0, 1, 2);
        add(0, 2, 3);
      } else {
        add(0, 1, 3);
        add(1, 2, 3);
      }
      continue;
    }
    for (int i = 1; i + 1 < count; ++i) add(0, i, i + 1);
  }
  if (skipped > 0)
    soup->notes.push_back(std::to_string(skipped) + " faces of fewer than 3 corners skipped");
  return Status::ok();
}

// The texture as CV_8UC3 BGR, whatever the file holds (grey, alpha, 16 bits).
Result<cv::Mat> read_texture(const fs::path& path) {
  GVKIT_ASSIGN_OR_RETURN(cv::Mat image, read_image(path));
  if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1.0 / 257.0);
  if (image.channels() == 1) cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);
  return image;
}

}  // namespace

Status TriangleSoupReadOptions::check() const {
  if (!(scale > 0 && std::isfinite(scale)))
    return invalid_argument("mesh scale must be > 0, got " + std::to_string(scale));
  return Status::ok();
}

Result<TriangleSoup> read_triangle_soup(const fs::path& path,
                                        const TriangleSoupReadOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found(path.string() + ": no such file");
  const std::string ext = lower_extension(path);
  if (ext != ".ply" && ext != ".obj")
    return unsupported(path.string() + ": unknown mesh format '" + ext + "' (use .ply or .obj)");
  if (fs::is_directory(path, ec)) return invalid_argument(path.string() + ": is a folder");
  GVKIT_ASSIGN_OR_RETURN(const std::string bytes, read_file(path));
  if (bytes.find_first_not_of(" \t\r\n") == std::string::npos)
    return corrupt_data(path.string() + ": empty file");

  TriangleSoup soup;
  detail::SoupPolygons polygons;
  GVKIT_RETURN_IF_ERROR(ext == ".ply" ? detail::read_ply_soup(path, bytes, &soup, &polygons)
                                      : detail::read_obj_soup(path, bytes, &soup, &polygons));
  if (!polygons.corner_uv.empty()) polygons.corner_uv.resize(polygons.corner_point.size());
  if (soup.points.empty()) return corrupt_data(path.string() + ": no vertices (an empty mesh)");
  GVKIT_RETURN_IF_ERROR(triangulate(path, polygons, &soup));
  if (soup.triangles.empty())
    return corrupt_data(path.string() + ": " + std::to_string(soup.points.size()) +
                        " vertices but no faces (a point cloud?); a mesh is needed");
  if (options.scale != 1.0)
    for (auto& p : soup.points) p *= options.scale;

  // Textures: a file that cannot be read leaves its triangles untextured.
  if (soup.has_texture()) {
    soup.textures.resize(soup.texture_paths.size());
    std::vector<char> usable(soup.texture_paths.size(), 1);
    for (size_t i = 0; i < soup.texture_paths.size() && options.read_textures; ++i) {
      auto image = read_texture(soup.texture_paths[i]);
      if (image.is_ok()) {
        soup.textures[i] = std::move(image).value();
      } else {
        usable[i] = 0;
        soup.notes.push_back(image.status().message() + "; its faces have no texture");
      }
    }
    bool any = false;
    for (int& t : soup.triangle_texture) {
      if (t >= 0 && !usable[t]) t = -1;
      any |= t >= 0;
    }
    if (!any) {
      soup.triangle_texture.clear();
      soup.corner_uv.clear();
    }
  }
  return soup;
}

Status write_triangle_soup(const fs::path& path, const TriangleSoup& soup) {
  const std::string ext = lower_extension(path);
  if (ext != ".ply" && ext != ".obj")
    return unsupported(path.string() + ": unknown mesh format '" + ext + "' (use .ply or .obj)");
  const bool colours = !soup.colors.empty() && soup.colors.size() == soup.points.size();
  const bool uv = soup.has_texture() && soup.triangle_texture.size() == soup.triangles.size() &&
                  soup.corner_uv.size() == soup.triangles.size();
  std::string out;
  char buffer[256];
  if (ext == ".ply") {
    out += "ply\nformat binary_little_endian 1.0\ncomment written by gvkit (triangle soup)\n";
    if (uv && !soup.texture_paths.empty())
      out += "comment TextureFile " + soup.texture_paths.front().filename().string() + "\n";
    out += "element vertex " + std::to_string(soup.points.size()) + "\n";
    out += "property double x\nproperty double y\nproperty double z\n";
    if (colours) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    out += "element face " + std::to_string(soup.triangles.size()) + "\n";
    out += "property list uchar int vertex_indices\n";
    if (uv) out += "property list uchar float texcoord\n";
    out += "end_header\n";
    auto put = [&](const void* data, size_t size) {
      out.append(static_cast<const char*>(data), size);
    };
    for (size_t i = 0; i < soup.points.size(); ++i) {
      for (int k = 0; k < 3; ++k) put(&soup.points[i][k], 8);
      if (colours)
        for (int k = 0; k < 3; ++k) {
          const auto c = static_cast<unsigned char>(
              std::lround(std::clamp(soup.colors[i][k], 0.0f, 1.0f) * 255.0f));
          put(&c, 1);
        }
    }
    for (size_t t = 0; t < soup.triangles.size(); ++t) {
      const unsigned char three = 3, six = 6;
      put(&three, 1);
      for (int k = 0; k < 3; ++k) put(&soup.triangles[t][k], 4);
      if (uv) {
        put(&six, 1);
        for (int k = 0; k < 3; ++k)
          for (int j = 0; j < 2; ++j) put(&soup.corner_uv[t][k][j], 4);
      }
    }
    return write_file_atomically(path, out);
  }
  // OBJ, with a .mtl naming the textures when there are texture coordinates.
  const fs::path mtl = fs::path(path).replace_extension(".mtl");
  if (uv) {
    out += "mtllib " + mtl.filename().string() + "\n";
    std::string materials;
    for (size_t i = 0; i < soup.texture_paths.size(); ++i)
      materials += "newmtl texture" + std::to_string(i) + "\nKd 1 1 1\nmap_Kd " +
                   soup.texture_paths[i].filename().string() + "\n";
    GVKIT_RETURN_IF_ERROR(write_file_atomically(mtl, materials));
  }
  for (size_t i = 0; i < soup.points.size(); ++i) {
    const auto& p = soup.points[i];
    if (colours)
      std::snprintf(buffer, sizeof buffer, "v %.9g %.9g %.9g %.6g %.6g %.6g\n", p[0], p[1], p[2],
                    soup.colors[i][0], soup.colors[i][1], soup.colors[i][2]);
    else
      std::snprintf(buffer, sizeof buffer, "v %.9g %.9g %.9g\n", p[0], p[1], p[2]);
    out += buffer;
  }
  if (uv)
    for (const auto& corners : soup.corner_uv)
      for (const auto& c : corners) {
        std::snprintf(buffer, sizeof buffer, "vt %.9g %.9g\n", c[0], c[1]);
        out += buffer;
      }
  int material = -2;
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    const auto& f = soup.triangles[t];
    const int texture = uv ? soup.triangle_texture[t] : -1;
    if (uv && texture != material && texture >= 0) {
      out += "usemtl texture" + std::to_string(texture) + "\n";
      material = texture;
    }
    if (texture >= 0)
      std::snprintf(buffer, sizeof buffer, "f %d/%zu %d/%zu %d/%zu\n", f[0] + 1, 3 * t + 1,
                    f[1] + 1, 3 * t + 2, f[2] + 1, 3 * t + 3);
    else
      std::snprintf(buffer, sizeof buffer, "f %d %d %d\n", f[0] + 1, f[1] + 1, f[2] + 1);
    out += buffer;
  }
  return write_file_atomically(path, out);
}

}  // namespace gvkit
