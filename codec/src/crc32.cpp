#include "gvkit/codec/crc32.hpp"

#include <algorithm>

#include <zlib.h>

namespace gvkit::codec {

// zlib's CRC-32 is this one (IEEE 802.3, reflected, initial and final value inverted, the
// running value passed back in as it is returned), computed several bytes at a time.
uint32_t crc32(const void* data, size_t size, uint32_t crc) {
  const auto* p = static_cast<const Bytef*>(data);
  uLong value = crc;
  while (size > 0) {
    const auto n = static_cast<uInt>(std::min<size_t>(size, size_t{1} << 30));
    value = ::crc32(value, p, n);
    p += n;
    size -= n;
  }
  return static_cast<uint32_t>(value);
}

}  // namespace gvkit::codec
