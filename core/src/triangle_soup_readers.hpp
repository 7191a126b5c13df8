#pragma once
// Internal: the PLY and OBJ parsers behind read_triangle_soup. Each fills points, colours and the
// file's polygons (corners as read, with their texture coordinates where the file has them) and
// the texture paths; read_triangle_soup then triangulates, scales and loads the textures.

#include <filesystem>
#include <string>
#include <vector>

#include "gvkit/core/triangle_soup.hpp"

namespace gvkit::detail {

struct SoupPolygons {
  std::vector<int> corner_point;     // point index of every corner, polygon after polygon
  std::vector<cv::Vec2f> corner_uv;  // per corner when any polygon has a texture, else empty
  std::vector<int> start{0};         // polygon k has corners start[k] .. start[k + 1] - 1
  std::vector<int> texture;          // per polygon: index into texture paths, -1 none

  int size() const { return static_cast<int>(texture.size()); }
};

// `bytes` is the whole file. Errors name `path` and the line (OBJ) or element record (PLY).
Status read_ply_soup(const std::filesystem::path& path, const std::string& bytes,
                     TriangleSoup* soup, SoupPolygons* polygons);
Status read_obj_soup(const std::filesystem::path& path, const std::string& bytes,
                     TriangleSoup* soup, SoupPolygons* polygons);

}  // namespace gvkit::detail
