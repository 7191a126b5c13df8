// Wavefront OBJ (+ its .mtl files) into a triangle soup: every face kept as the file has it.
#include <algorithm>
#include <cstdlib>
#include <map>
#include <string_view>

#include "gvkit/core/atomic_file.hpp"
#include "triangle_soup_readers.hpp"

namespace gvkit::detail {
namespace fs = std::filesystem;
namespace {

// The whitespace-separated words of a line.
std::vector<std::string_view> words_of(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

bool parse_number(std::string_view word, double* value) {
  const std::string text(word);
  char* end = nullptr;
  *value = std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size();
}

// An OBJ index (1-based, or negative: relative to the end) into a list of `count` items, as a
// 0-based index; -1 when it is zero or not a number. Range is checked by the caller.
long parse_index(std::string_view word, long count) {
  if (word.empty()) return -1;
  const std::string text(word);
  char* end = nullptr;
  const long i = std::strtol(text.c_str(), &end, 10);
  if (end != text.c_str() + text.size() || i == 0) return -1;
  return i > 0 ? i - 1 : count + i;
}

// Texture path of each material (map_Kd) in one .mtl file; missing files are noted.
void read_materials(const fs::path& mtl, std::map<std::string, fs::path>* maps,
                    std::vector<std::string>* notes) {
  auto text = read_file(mtl);
  if (!text.is_ok()) {
    notes->push_back(mtl.filename().string() + ": material file not readable; no texture");
    return;
  }
  std::string current;
  std::string_view rest = *text;
  while (!rest.empty()) {
    const size_t end = rest.find('\n');
    const std::string_view line = rest.substr(0, end);
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
    const auto words = words_of(line);
    if (words.size() < 2) continue;
    if (words[0] == "newmtl") {
      current = std::string(words[1]);
    } else if (words[0] == "map_Kd" && !current.empty()) {
      // Options (-s, -o, -bm ...) come first; the file name is the last word.
      std::string file(words.back());
      std::replace(file.begin(), file.end(), '\\', '/');
      (*maps)[current] = mtl.parent_path() / file;
    }
  }
}

}  // namespace

Status read_obj_soup(const fs::path& path, const std::string& bytes, TriangleSoup* soup,
                     SoupPolygons* polygons) {
  const std::string name = path.string();
  std::vector<cv::Vec2f> texcoords;
  std::map<std::string, fs::path> material_maps;
  std::map<fs::path, int> texture_of_path;
  int texture = -1;
  int coloured_points = 0;
  long line_number = 0;
  std::string_view rest = bytes;
  std::vector<std::pair<long, long>> corners;  // point, texcoord (-1 none) of the current face
  while (!rest.empty()) {
    const size_t end = rest.find('\n');
    const std::string_view line = rest.substr(0, end);
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
    ++line_number;
    if (line.empty() || line[0] == '#') continue;
    const auto words = words_of(line);
    if (words.empty()) continue;
    const std::string at = name + ": line " + std::to_string(line_number);
    const std::string_view keyword = words[0];
    if (keyword == "v") {
      double x[6] = {0, 0, 0, 0, 0, 0};
      const size_t n = std::min<size_t>(words.size() - 1, 6);
      if (n < 3) return corrupt_data(at + ": a vertex needs x y z");
      for (size_t i = 0; i < n; ++i)
        if (!parse_number(words[i + 1], &x[i]))
          return corrupt_data(at + ": '" + std::string(words[i + 1]) + "' is not a number");
      soup->points.emplace_back(x[0], x[1], x[2]);
      if (n == 6) {
        // Colours in [0, 1] (MeshLab, ZBrush), or 0..255 from some exporters.
        const double scale = std::max({x[3], x[4], x[5]}) > 1.0 ? 255.0 : 1.0;
        soup->colors.resize(soup->points.size(), Mesh::Color(0.5f, 0.5f, 0.5f, 1.0f));
        soup->colors.back() =
            Mesh::Color(static_cast<float>(std::clamp(x[3] / scale, 0.0, 1.0)),
                        static_cast<float>(std::clamp(x[4] / scale, 0.0, 1.0)),
                        static_cast<float>(std::clamp(x[5] / scale, 0.0, 1.0)), 1.0f);
        ++coloured_points;
      }
    } else if (keyword == "vt") {
      double uv[2] = {0, 0};
      if (words.size() < 2) return corrupt_data(at + ": a texture coordinate needs u [v]");
      for (size_t i = 0; i < std::min<size_t>(words.size() - 1, 2); ++i)
        if (!parse_number(words[i + 1], &uv[i]))
          return corrupt_data(at + ": '" + std::string(words[i + 1]) + "' is not a number");
      texcoords.emplace_back(static_cast<float>(uv[0]), static_cast<float>(uv[1]));
    } else if (keyword == "f") {
      corners.clear();
      for (size_t i = 1; i < words.size(); ++i) {
        const std::string_view w = words[i];
        const size_t slash = w.find('/');
        const long point = parse_index(w.substr(0, slash), static_cast<long>(soup->points.size()));
        if (point < 0 || point >= static_cast<long>(soup->points.size()))
          return corrupt_data(at + ": corner '" + std::string(w) + "' refers to no vertex (" +
                              std::to_string(soup->points.size()) + " defined so far)");
        long uv = -1;
        if (slash != std::string_view::npos) {
          const std::string_view second = w.substr(slash + 1, w.find('/', slash + 1) - slash - 1);
          if (!second.empty()) {
            uv = parse_index(second, static_cast<long>(texcoords.size()));
            if (uv < 0 || uv >= static_cast<long>(texcoords.size()))
              return corrupt_data(at + ": corner '" + std::string(w) +
                                  "' refers to no texture coordinate (" +
                                  std::to_string(texcoords.size()) + " defined so far)");
          }
        }
        corners.emplace_back(point, uv);
      }
      ++soup->polygons;
      const bool textured =
          texture >= 0 &&
          std::all_of(corners.begin(), corners.end(), [](const auto& c) { return c.second >= 0; });
      if (textured) polygons->corner_uv.resize(polygons->corner_point.size());
      for (const auto& [point, uv] : corners) {
        polygons->corner_point.push_back(static_cast<int>(point));
        if (textured) polygons->corner_uv.push_back(texcoords[uv]);
      }
      polygons->start.push_back(static_cast<int>(polygons->corner_point.size()));
      polygons->texture.push_back(textured ? texture : -1);
    } else if (keyword == "mtllib") {
      for (size_t i = 1; i < words.size(); ++i) {
        std::string file(words[i]);
        std::replace(file.begin(), file.end(), '\\', '/');
        read_materials(path.parent_path() / file, &material_maps, &soup->notes);
      }
    } else if (keyword == "usemtl") {
      texture = -1;
      const auto found = material_maps.find(words.size() > 1 ? std::string(words[1]) : "");
      if (found != material_maps.end()) {
        auto [it, added] =
            texture_of_path.emplace(found->second, static_cast<int>(soup->texture_paths.size()));
        if (added) soup->texture_paths.push_back(found->second);
        texture = it->second;
      }
    }
    // vn, vp, o, g, s, l, p and anything else: not needed for the surface.
  }
  if (coloured_points > 0 && coloured_points < static_cast<int>(soup->points.size())) {
    soup->notes.push_back(std::to_string(coloured_points) + " of " +
                          std::to_string(soup->points.size()) +
                          " vertices have colours: colours ignored");
    soup->colors.clear();
  }
  if (soup->texture_paths.empty() && !texcoords.empty())
    soup->notes.push_back("texture coordinates but no material with map_Kd: no texture");
  return Status::ok();
}

}  // namespace gvkit::detail
