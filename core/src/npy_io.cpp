#include "gvkit/core/npy_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "gvkit/core/atomic_file.hpp"

namespace gvkit {
namespace fs = std::filesystem;
namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr size_t kMagicSize = 6;

// The text after `key': ` in the header dict, up to the end of its value (a quoted string, a
// tuple or a word).
bool dict_value(const std::string& header, const std::string& key, std::string* value) {
  size_t at = header.find("'" + key + "'");
  if (at == std::string::npos) at = header.find("\"" + key + "\"");
  if (at == std::string::npos) return false;
  at = header.find(':', at);
  if (at == std::string::npos) return false;
  at = header.find_first_not_of(" ", at + 1);
  if (at == std::string::npos) return false;
  size_t end;
  if (header[at] == '\'' || header[at] == '"') {
    end = header.find(header[at], at + 1);
    if (end == std::string::npos) return false;
    *value = header.substr(at + 1, end - at - 1);
  } else if (header[at] == '(') {
    end = header.find(')', at);
    if (end == std::string::npos) return false;
    *value = header.substr(at + 1, end - at - 1);
  } else {
    end = header.find_first_of(",}", at);
    if (end == std::string::npos) return false;
    *value = header.substr(at, end - at);
    while (!value->empty() && value->back() == ' ') value->pop_back();
  }
  return true;
}

double half_to_double(uint16_t h) {
  const int sign = (h >> 15) ? -1 : 1, exponent = (h >> 10) & 0x1f, mantissa = h & 0x3ff;
  if (exponent == 0) return sign * std::ldexp(mantissa, -24);
  if (exponent == 31) return mantissa ? NAN : sign * INFINITY;
  return sign * std::ldexp(mantissa + 1024, exponent - 25);
}

}  // namespace

Result<NpyArray> read_npy(const fs::path& path) {
  const std::string name = path.string();
  GVKIT_ASSIGN_OR_RETURN(const std::string bytes, read_file(path));
  if (bytes.size() < kMagicSize + 4 || bytes.compare(0, kMagicSize, kMagic, kMagicSize) != 0)
    return corrupt_data(name + ": not a NumPy .npy file (no \\x93NUMPY magic)");
  const int major = static_cast<unsigned char>(bytes[6]);
  size_t header_len = 0, header_start = 0;
  if (major == 1) {
    header_len = static_cast<unsigned char>(bytes[8]) | static_cast<unsigned char>(bytes[9]) << 8;
    header_start = 10;
  } else if (major == 2 || major == 3) {
    if (bytes.size() < 12) return corrupt_data(name + ": truncated .npy header");
    for (int i = 0; i < 4; ++i)
      header_len |= static_cast<size_t>(static_cast<unsigned char>(bytes[8 + i])) << (8 * i);
    header_start = 12;
  } else {
    return unsupported(name + ": .npy format version " + std::to_string(major) + " unknown");
  }
  if (header_start + header_len > bytes.size())
    return corrupt_data(name + ": truncated .npy header");
  const std::string header = bytes.substr(header_start, header_len);
  NpyArray array;
  std::string fortran, shape;
  if (!dict_value(header, "descr", &array.dtype) || !dict_value(header, "shape", &shape) ||
      !dict_value(header, "fortran_order", &fortran))
    return corrupt_data(name + ": .npy header without descr, fortran_order and shape: " + header);
  // dtype: byte order, kind, size.
  const std::string& d = array.dtype;
  if (d.size() < 3 || std::string("<>|=").find(d[0]) == std::string::npos)
    return unsupported(name + ": .npy dtype '" + d + "' is not a plain number type");
  const char kind = d[1];
  const int size = std::atoi(d.c_str() + 2);
  const bool big_endian = d[0] == '>';
  const bool known =
      (kind == 'f' && (size == 2 || size == 4 || size == 8)) ||
      ((kind == 'i' || kind == 'u') && (size == 1 || size == 2 || size == 4 || size == 8)) ||
      (kind == 'b' && size == 1);
  if (!known) return unsupported(name + ": .npy dtype '" + d + "' is not supported (numbers only)");
  // Shape: "68, 2" or "68," or "".
  size_t count = 1;
  for (size_t at = 0; at < shape.size();) {
    const size_t end = std::min(shape.find(',', at), shape.size());
    const std::string item = shape.substr(at, end - at);
    at = end + 1;
    if (item.find_first_not_of(" ") == std::string::npos) continue;
    char* stop = nullptr;
    const long long n = std::strtoll(item.c_str(), &stop, 10);
    if (n < 0 || (*stop != '\0' && std::string(stop).find_first_not_of(" L") != std::string::npos))
      return corrupt_data(name + ": .npy shape '(" + shape + ")' does not parse");
    array.shape.push_back(static_cast<size_t>(n));
    if (n > 0 && count > (size_t{1} << 40) / static_cast<size_t>(n))
      return corrupt_data(name + ": .npy shape '(" + shape + ")' is too large");
    count *= static_cast<size_t>(n);
  }
  const size_t data_start = header_start + header_len;
  if (bytes.size() - data_start < count * size)
    return corrupt_data(name + ": truncated .npy data (" +
                        std::to_string(bytes.size() - data_start) + " bytes for " +
                        std::to_string(count) + " values of " + std::to_string(size) + " bytes)");
  std::vector<double> raw(count);
  for (size_t i = 0; i < count; ++i) {
    unsigned char b[8];
    std::memcpy(b, bytes.data() + data_start + i * size, size);
    if (big_endian) std::reverse(b, b + size);
    double v = 0;
    if (kind == 'f' && size == 2) {
      uint16_t h;
      std::memcpy(&h, b, 2);
      v = half_to_double(h);
    } else if (kind == 'f' && size == 4) {
      float f;
      std::memcpy(&f, b, 4);
      v = f;
    } else if (kind == 'f') {
      std::memcpy(&v, b, 8);
    } else {
      uint64_t u = 0;
      std::memcpy(&u, b, size);  // little endian host
      if (kind == 'i' && size < 8 && (u >> (8 * size - 1)) & 1) u |= ~uint64_t{0} << (8 * size);
      v = kind == 'i' ? static_cast<double>(static_cast<int64_t>(u)) : static_cast<double>(u);
    }
    raw[i] = v;
  }
  const bool fortran_order = fortran.find("True") != std::string::npos;
  if (!fortran_order || array.shape.size() < 2) {
    array.values = std::move(raw);
    return array;
  }
  // Fortran order: the first index varies fastest.
  array.values.resize(count);
  const size_t dims = array.shape.size();
  std::vector<size_t> index(dims, 0);
  for (size_t f = 0; f < count; ++f) {
    size_t c = 0;
    for (size_t k = 0; k < dims; ++k) c = c * array.shape[k] + index[k];
    array.values[c] = raw[f];
    for (size_t k = 0; k < dims && ++index[k] == array.shape[k]; ++k) index[k] = 0;
  }
  return array;
}

Status write_npy(const fs::path& path, const std::vector<size_t>& shape,
                 const std::vector<double>& values, NpyType type) {
  size_t count = 1;
  for (size_t n : shape) count *= n;
  if (count != values.size())
    return invalid_argument(path.string() + ": " + std::to_string(values.size()) +
                            " values for a shape of " + std::to_string(count));
  std::string dict = std::string("{'descr': '") + (type == NpyType::kFloat32 ? "<f4" : "<f8") +
                     "', 'fortran_order': False, 'shape': (";
  for (size_t n : shape) dict += std::to_string(n) + ", ";
  if (!shape.empty()) dict.erase(dict.size() - (shape.size() == 1 ? 1 : 2));
  dict += "), }";
  // Header padded with spaces to a multiple of 64 bytes, ending in a newline.
  const size_t total = (10 + dict.size() + 1 + 63) / 64 * 64;
  dict.append(total - 10 - dict.size() - 1, ' ');
  dict += '\n';
  std::string out(kMagic, kMagicSize);
  out += '\x01';
  out += '\x00';
  out += static_cast<char>(dict.size() & 0xff);
  out += static_cast<char>(dict.size() >> 8);
  out += dict;
  for (double v : values) {
    if (type == NpyType::kFloat32) {
      const float f = static_cast<float>(v);
      out.append(reinterpret_cast<const char*>(&f), 4);
    } else {
      out.append(reinterpret_cast<const char*>(&v), 8);
    }
  }
  return write_file_atomically(path, out);
}

}  // namespace gvkit
