#pragma once
// NumPy .npy arrays (format versions 1.0-3.0): numeric dtypes (float16/32/64, signed and unsigned
// integers of 1-8 bytes, bool), either byte order, C or Fortran order. Values are returned as
// doubles in C (row-major) order. Written as little-endian float64 or float32, C order; atomic.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "gvkit/core/status.hpp"

namespace gvkit {

struct NpyArray {
  std::vector<size_t> shape;   // empty for a scalar
  std::vector<double> values;  // product of shape, C order
  std::string dtype;           // as in the file, e.g. "<f4"
};

// Fails naming the file when it is missing, not an .npy (magic), has a header that does not
// parse, an unsupported dtype (strings, objects, complex, structured), or less data than its
// shape needs.
Result<NpyArray> read_npy(const std::filesystem::path& path);

enum class NpyType { kFloat32, kFloat64 };
Status write_npy(const std::filesystem::path& path, const std::vector<size_t>& shape,
                 const std::vector<double>& values, NpyType type = NpyType::kFloat64);

}  // namespace gvkit
