#pragma once
// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320), as used by zlib and PNG. Protects every
// header and packet of a .gvid stream.

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace gvkit::codec {

// CRC of bytes, continuing from a previous crc (0 to start).
uint32_t crc32(const void* data, size_t size, uint32_t crc = 0);
inline uint32_t crc32(std::string_view bytes) { return crc32(bytes.data(), bytes.size()); }

}  // namespace gvkit::codec
