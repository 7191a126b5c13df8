#pragma once
// CRC-8 (polynomial x^8 + x^2 + x + 1, 0x07, initial value 0, no reflection, no final xor: the
// CRC-8/SMBUS of the catalogues; check value 0xF4 for "123456789"). Protects the compact packet
// header of a .gvid stream (format 1.10), whose payload carries its own CRC-32.

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace gvkit::codec {

uint8_t crc8(const void* data, size_t size);
inline uint8_t crc8(std::string_view bytes) { return crc8(bytes.data(), bytes.size()); }

}  // namespace gvkit::codec
