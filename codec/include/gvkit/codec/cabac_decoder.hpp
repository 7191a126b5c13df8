#pragma once
// CABAC binary arithmetic decoder (H.264 clause 9.3.3.2), the mirror of CabacEncoder. Reading
// past the end of the data yields zero bits (never out of bounds); overrun() tells whether that
// went further than a correct stream ever needs, which callers report as corrupt data.

#include <cstdint>
#include <string_view>

#include "gvkit/codec/cabac_context.hpp"

namespace gvkit::codec {

class CabacDecoder {
 public:
  explicit CabacDecoder(std::string_view data);
  int decode(CabacContext& ctx);
  int decode_bypass();
  int decode_terminate();
  // True when more than 16 bits past the end of the data were consumed.
  bool overrun() const { return bit_pos_ > data_bits_ + 16; }

 private:
  // Next n bits (n <= 24) of the segment, MSB first; zeros past its end.
  uint32_t read_bits(int n) {
    if (cache_bits_ < n) refill();
    cache_bits_ -= n;
    bit_pos_ += static_cast<uint64_t>(n);
    return static_cast<uint32_t>(cache_ >> cache_bits_) & ((1u << n) - 1);
  }
  void refill() {
    while (cache_bits_ <= 56) {
      const uint8_t byte = byte_pos_ < data_.size() ? static_cast<uint8_t>(data_[byte_pos_]) : 0;
      ++byte_pos_;
      cache_ = (cache_ << 8) | byte;
      cache_bits_ += 8;
    }
  }
  void renormalize() {
    if (range_ < 256) {
      const int n = __builtin_clz(range_) - 23;
      range_ <<= n;
      offset_ = (offset_ << n) | read_bits(n);
    }
  }
  std::string_view data_;
  uint64_t data_bits_;
  uint64_t bit_pos_ = 0;
  uint64_t cache_ = 0;
  int cache_bits_ = 0;
  size_t byte_pos_ = 0;
  uint32_t range_ = 510, offset_ = 0;
};

}  // namespace gvkit::codec
