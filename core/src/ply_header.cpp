#include "ply_header.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace gvkit::detail {
namespace {

constexpr size_t kMaxHeaderBytes = 64 * 1024;

int scalar_size(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" ||
      type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

struct Element {
  std::string name;
  uint64_t count = 0;
  uint64_t min_record_bytes = 0;  // binary: bytes of one record with lists of length 3 (faces)
};

}  // namespace

Status check_ply_structure(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) return io_error(name + ": cannot open");
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0)
    return corrupt_data(name + ": not a PLY file (no 'ply' magic)");
  std::string format;
  std::vector<Element> elements;
  bool end_header = false;
  while (std::getline(in, line)) {
    if (static_cast<size_t>(in.tellg()) > kMaxHeaderBytes) break;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "end_header") {
      end_header = true;
      break;
    }
    if (keyword == "format") {
      words >> format;
    } else if (keyword == "element") {
      Element e;
      long long count = -1;
      words >> e.name >> count;
      if (!words || count < 0) return corrupt_data(name + ": bad element line '" + line + "'");
      e.count = static_cast<uint64_t>(count);
      elements.push_back(e);
    } else if (keyword == "property") {
      if (elements.empty()) return corrupt_data(name + ": property before any element");
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type;
        const int c = scalar_size(count_type), i = scalar_size(item_type);
        if (!c || !i) return corrupt_data(name + ": unknown list type in '" + line + "'");
        elements.back().min_record_bytes += c + 3 * i;
      } else {
        const int s = scalar_size(type);
        if (!s) return corrupt_data(name + ": unknown property type in '" + line + "'");
        elements.back().min_record_bytes += s;
      }
    }
  }
  if (!end_header) return corrupt_data(name + ": PLY header has no end_header");
  if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
    return corrupt_data(name + ": unknown PLY format '" + format + "'");

  const auto body_start = static_cast<uint64_t>(in.tellg());
  std::error_code ec;
  const uint64_t file_size = std::filesystem::file_size(path, ec);
  if (ec) return io_error(name + ": cannot stat: " + ec.message());
  const uint64_t body = file_size - body_start;
  if (format == "ascii") {
    uint64_t needed = 0;
    for (const auto& e : elements) needed += e.count;
    // Every record takes at least two bytes ("0\n"); bail out before counting lines of absurd
    // headers.
    if (needed > body / 2 + 1)
      return corrupt_data(name + ": truncated (header declares " + std::to_string(needed) +
                          " records, the body is " + std::to_string(body) + " bytes)");
    uint64_t lines = 0;
    while (std::getline(in, line))
      if (line.find_first_not_of(" \t\r") != std::string::npos) ++lines;
    if (lines < needed)
      return corrupt_data(name + ": truncated (" + std::to_string(lines) + " of " +
                          std::to_string(needed) + " records)");
  } else {
    uint64_t needed = 0;
    for (const auto& e : elements) {
      if (e.min_record_bytes && e.count > body / e.min_record_bytes + 1)
        return corrupt_data(name + ": truncated (element " + e.name + " declares " +
                            std::to_string(e.count) + " records)");
      needed += e.count * e.min_record_bytes;
    }
    if (body < needed)
      return corrupt_data(name + ": truncated (body has " + std::to_string(body) +
                          " bytes, the header needs at least " + std::to_string(needed) + ")");
  }
  return Status::ok();
}

}  // namespace gvkit::detail
