#pragma once
// The pixel data of one chunk of an OpenEXR scanline file in OpenEXR's ZIP and ZIPS compression
// (the same coding; ZIP chunks hold 16 scanlines, ZIPS chunks one): the chunk's bytes are split
// into the even-indexed and the odd-indexed ones, one half after the other; each byte is then
// stored as its difference to the byte before it plus 128 (mod 256), and the result is a zlib
// stream (RFC 1950). A chunk whose zlib stream would not be smaller than its bytes is stored as
// they are. Deflated and inflated by libdeflate, about twice as fast as the zlib that OpenEXR
// 3.1 calls (OpenEXR 3.2 moved to libdeflate for the same reason; docs/benchmarks.md, "EXR ZIP
// chunks by libdeflate").
//
// The coder owns libdeflate's state: one per thread (not thread-safe), reusable across chunks.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

struct libdeflate_compressor;
struct libdeflate_decompressor;

namespace gvkit::detail {

class ExrZipChunkCoder {
 public:
  // level: zlib's 1 (fastest) .. 9 (smallest); OpenEXR 3.1 writes at 4.
  explicit ExrZipChunkCoder(int level = 4);
  ~ExrZipChunkCoder();
  ExrZipChunkCoder(const ExrZipChunkCoder&) = delete;
  ExrZipChunkCoder& operator=(const ExrZipChunkCoder&) = delete;

  // The stored form of raw[0, size) (size > 0): the zlib stream, or the bytes themselves when
  // that is not smaller. The returned bytes live until the next call.
  const std::vector<uint8_t>& pack(const uint8_t* raw, size_t size);

  // The chunk's size bytes from its stored form (packed_size bytes): false when the stored
  // form is larger than size, or is not a zlib stream of exactly size bytes.
  bool unpack(const uint8_t* packed, size_t packed_size, uint8_t* raw, size_t size);

 private:
  int level_;
  libdeflate_compressor* compressor_ = nullptr;  // made on the first pack
  libdeflate_decompressor* decompressor_ = nullptr;
  std::vector<uint8_t> scratch_, packed_;
};

}  // namespace gvkit::detail
