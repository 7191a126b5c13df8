// PLY (ascii, binary little/big endian) into a triangle soup: every face kept as the file has it.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "ply_header.hpp"
#include "triangle_soup_readers.hpp"

namespace gvkit::detail {
namespace fs = std::filesystem;
namespace {

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

bool parse_type(const std::string& name, PlyType* type) {
  static const std::pair<const char*, PlyType> kNames[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [n, t] : kNames)
    if (name == n) {
      *type = t;
      return true;
    }
  return false;
}

int type_size(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

// The full-scale value of an integer colour channel (1 for floating point).
double colour_scale(PlyType t) {
  switch (t) {
    case PlyType::kUint8:
    case PlyType::kInt8:
      return 255.0;
    case PlyType::kUint16:
    case PlyType::kInt16:
      return 65535.0;
    case PlyType::kFloat32:
    case PlyType::kFloat64:
      return 1.0;
    default:
      return 4294967295.0;
  }
}

struct Property {
  std::string name;
  PlyType type = PlyType::kFloat32;
  bool list = false;
  PlyType count_type = PlyType::kUint8;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
};

// Reads scalars from the body: whitespace-separated tokens one record per line (ascii), or
// packed values of the declared sizes (binary). Every read says whether the value was there.
class BodyReader {
 public:
  BodyReader(const std::string& bytes, size_t start, bool ascii, bool big_endian)
      : bytes_(bytes), pos_(start), ascii_(ascii), big_endian_(big_endian) {}

  // ascii: moves to the next non-blank line (one record); binary: nothing to do.
  bool start_record() {
    if (!ascii_) return true;
    while (pos_ < bytes_.size()) {
      size_t end = bytes_.find('\n', pos_);
      if (end == std::string::npos) end = bytes_.size();
      line_ = std::string_view(bytes_).substr(pos_, end - pos_);
      pos_ = end + 1;
      if (line_.find_first_not_of(" \t\r") != std::string_view::npos) return true;
    }
    return false;
  }

  bool read(PlyType type, double* value) {
    if (ascii_) {
      const size_t first = line_.find_first_not_of(" \t\r");
      if (first == std::string_view::npos) return false;
      size_t last = line_.find_first_of(" \t\r", first);
      if (last == std::string_view::npos) last = line_.size();
      const std::string token(line_.substr(first, last - first));
      line_ = line_.substr(last);
      char* end = nullptr;
      *value = std::strtod(token.c_str(), &end);
      return end == token.c_str() + token.size();
    }
    const int size = type_size(type);
    if (pos_ + size > bytes_.size()) return false;
    unsigned char b[8];
    std::memcpy(b, bytes_.data() + pos_, size);
    pos_ += size;
    if (big_endian_) std::reverse(b, b + size);
    switch (type) {
      case PlyType::kInt8:
        *value = static_cast<int8_t>(b[0]);
        break;
      case PlyType::kUint8:
        *value = b[0];
        break;
      case PlyType::kInt16: {
        int16_t v;
        std::memcpy(&v, b, 2);
        *value = v;
        break;
      }
      case PlyType::kUint16: {
        uint16_t v;
        std::memcpy(&v, b, 2);
        *value = v;
        break;
      }
      case PlyType::kInt32: {
        int32_t v;
        std::memcpy(&v, b, 4);
        *value = v;
        break;
      }
      case PlyType::kUint32: {
        uint32_t v;
        std::memcpy(&v, b, 4);
        *value = v;
        break;
      }
      case PlyType::kFloat32: {
        float v;
        std::memcpy(&v, b, 4);
        *value = v;
        break;
      }
      case PlyType::kFloat64: {
        double v;
        std::memcpy(&v, b, 8);
        *value = v;
        break;
      }
    }
    return true;
  }

  size_t remaining() const { return ascii_ ? line_.size() : bytes_.size() - pos_; }

 private:
  const std::string& bytes_;
  size_t pos_;
  bool ascii_, big_endian_;
  std::string_view line_;
};

bool is_one_of(const std::string& name, std::initializer_list<const char*> names) {
  for (const char* n : names)
    if (name == n) return true;
  return false;
}

}  // namespace

Status read_ply_soup(const fs::path& path, const std::string& bytes, TriangleSoup* soup,
                     SoupPolygons* polygons) {
  const std::string name = path.string();
  GVKIT_RETURN_IF_ERROR(check_ply_structure(path));
  // Header (check_ply_structure has seen "ply", the format and end_header).
  std::istringstream header(bytes.substr(0, std::min<size_t>(bytes.size(), 64 * 1024)));
  std::string line, format;
  std::vector<Element> elements;
  std::vector<std::string> texture_names;
  size_t body_start = 0;
  while (std::getline(header, line)) {
    body_start += line.size() + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "end_header") break;
    if (keyword == "format") {
      words >> format;
    } else if (keyword == "comment") {
      std::string what;
      words >> what;
      if (what == "TextureFile") {
        std::string rest;
        std::getline(words, rest);
        rest.erase(0, rest.find_first_not_of(" \t"));
        if (!rest.empty()) texture_names.push_back(rest);
      }
    } else if (keyword == "element") {
      Element e;
      words >> e.name >> e.count;
      elements.push_back(e);
    } else if (keyword == "property") {
      Property p;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type;
        p.list = true;
        if (!parse_type(count_type, &p.count_type) || !parse_type(item_type, &p.type))
          return corrupt_data(name + ": unknown list type in '" + line + "'");
      } else if (!parse_type(type, &p.type)) {
        return corrupt_data(name + ": unknown property type in '" + line + "'");
      }
      words >> p.name;
      elements.back().properties.push_back(p);
    }
  }
  const bool ascii = format == "ascii";
  BodyReader body(bytes, body_start, ascii, format == "binary_big_endian");
  for (const auto& t : texture_names) soup->texture_paths.push_back(path.parent_path() / t);

  bool have_vertices = false, vertex_uv = false, any_uv = false;
  std::vector<cv::Vec2f> point_uv;
  for (const Element& e : elements) {
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    if (is_vertex && have_vertices) return corrupt_data(name + ": more than one vertex element");
    // Which property fills what.
    enum Role { kSkip, kX, kY, kZ, kR, kG, kB, kU, kV, kCorners, kTexcoords, kTexNumber };
    std::vector<Role> roles;
    bool has_xyz[3] = {false, false, false}, has_colour = false, has_corners = false;
    for (const Property& p : e.properties) {
      Role r = kSkip;
      if (is_vertex && !p.list) {
        if (p.name == "x") r = kX, has_xyz[0] = true;
        if (p.name == "y") r = kY, has_xyz[1] = true;
        if (p.name == "z") r = kZ, has_xyz[2] = true;
        if (is_one_of(p.name, {"red", "r", "diffuse_red"})) r = kR, has_colour = true;
        if (is_one_of(p.name, {"green", "g", "diffuse_green"})) r = kG;
        if (is_one_of(p.name, {"blue", "b", "diffuse_blue"})) r = kB;
        if (is_one_of(p.name, {"u", "s", "texture_u", "texture_s"})) r = kU, vertex_uv = true;
        if (is_one_of(p.name, {"v", "t", "texture_v", "texture_t"})) r = kV;
      } else if (is_face) {
        if (p.list && is_one_of(p.name, {"vertex_indices", "vertex_index"}))
          r = kCorners, has_corners = true;
        if (p.list && p.name == "texcoord") r = kTexcoords;
        if (!p.list && p.name == "texnumber") r = kTexNumber;
      }
      roles.push_back(r);
    }
    if (is_vertex) {
      if (!has_xyz[0] || !has_xyz[1] || !has_xyz[2])
        return corrupt_data(name + ": the vertex element has no x, y and z");
      have_vertices = true;
      soup->points.resize(e.count);
      if (has_colour) soup->colors.assign(e.count, Mesh::Color(0.5f, 0.5f, 0.5f, 1.0f));
      if (vertex_uv) point_uv.assign(e.count, cv::Vec2f(0, 0));
    }
    if (is_face && !has_corners)
      return corrupt_data(name + ": the face element has no vertex_indices list");
    std::vector<double> values;
    for (uint64_t k = 0; k < e.count; ++k) {
      auto truncated = [&](const Property& p) {
        return corrupt_data(name + ": " + e.name + " " + std::to_string(k) + ": no value for " +
                            p.name + " (truncated or malformed)");
      };
      if (!body.start_record())
        return corrupt_data(name + ": truncated in " + e.name + " " + std::to_string(k) + " of " +
                            std::to_string(e.count));
      int texnumber = 0;
      bool has_texcoords = false;
      std::vector<cv::Vec2f> texcoords;
      const int polygon_start = static_cast<int>(polygons->corner_point.size());
      for (size_t i = 0; i < e.properties.size(); ++i) {
        const Property& p = e.properties[i];
        if (p.list) {
          double count = 0;
          if (!body.read(p.count_type, &count)) return truncated(p);
          // Each item takes at least one byte (binary) or two characters (ascii).
          if (!(count >= 0) || count != std::floor(count) || count > body.remaining())
            return corrupt_data(name + ": " + e.name + " " + std::to_string(k) + ": bad " + p.name +
                                " length " + std::to_string(count));
          values.resize(static_cast<size_t>(count));
          for (double& v : values)
            if (!body.read(p.type, &v)) return truncated(p);
          if (roles[i] == kCorners) {
            for (double v : values) {
              if (v != std::floor(v) || !(std::abs(v) < 2147483647.0))
                return corrupt_data(name + ": face " + std::to_string(k) +
                                    ": corner index is not an integer");
              polygons->corner_point.push_back(static_cast<int>(v));
            }
          } else if (roles[i] == kTexcoords && values.size() % 2 == 0) {
            has_texcoords = true;
            for (size_t j = 0; j + 1 < values.size(); j += 2)
              texcoords.emplace_back(static_cast<float>(values[j]),
                                     static_cast<float>(values[j + 1]));
          }
          continue;
        }
        double v = 0;
        if (!body.read(p.type, &v)) return truncated(p);
        const Role r = roles[i];
        if (r == kX || r == kY || r == kZ) soup->points[k][r - kX] = v;
        if (r == kR || r == kG || r == kB)
          soup->colors[k][r - kR] =
              static_cast<float>(std::clamp(v / colour_scale(p.type), 0.0, 1.0));
        if (r == kU) point_uv[k][0] = static_cast<float>(v);
        if (r == kV) point_uv[k][1] = static_cast<float>(v);
        if (r == kTexNumber) texnumber = v >= 0 && v < 1e6 ? static_cast<int>(v) : -1;
      }
      if (!is_face) continue;
      ++soup->polygons;
      const int corners = static_cast<int>(polygons->corner_point.size()) - polygon_start;
      polygons->start.push_back(static_cast<int>(polygons->corner_point.size()));
      int texture = -1;
      if (has_texcoords && static_cast<int>(texcoords.size()) == corners) {
        any_uv = true;
        texture = texnumber;
        polygons->corner_uv.resize(polygon_start);
        polygons->corner_uv.insert(polygons->corner_uv.end(), texcoords.begin(), texcoords.end());
      } else if (vertex_uv) {
        any_uv = true;
        texture = 0;
        polygons->corner_uv.resize(polygon_start);
        for (int c = polygon_start; c < polygon_start + corners; ++c) {
          const int point = polygons->corner_point[c];
          polygons->corner_uv.push_back(point >= 0 && point < static_cast<int>(point_uv.size())
                                            ? point_uv[point]
                                            : cv::Vec2f(0, 0));
        }
      }
      if (texture < 0 || texture >= static_cast<int>(soup->texture_paths.size())) texture = -1;
      polygons->texture.push_back(texture);
    }
  }
  if (!have_vertices) return corrupt_data(name + ": no vertex element");
  if (any_uv && soup->texture_paths.empty())
    soup->notes.push_back("texture coordinates but no 'comment TextureFile': no texture");
  return Status::ok();
}

}  // namespace gvkit::detail
