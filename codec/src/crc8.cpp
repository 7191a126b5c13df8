#include "gvkit/codec/crc8.hpp"

namespace gvkit::codec {

uint8_t crc8(const void* data, size_t size) {
  const auto* p = static_cast<const uint8_t*>(data);
  uint8_t crc = 0;
  for (size_t i = 0; i < size; ++i) {
    crc ^= p[i];
    for (int k = 0; k < 8; ++k)
      crc = static_cast<uint8_t>((crc & 0x80) ? (crc << 1) ^ 0x07 : crc << 1);
  }
  return crc;
}

}  // namespace gvkit::codec
