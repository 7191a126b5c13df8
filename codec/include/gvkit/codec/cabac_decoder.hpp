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
  int read_bit() {
    const uint64_t pos = bit_pos_++;
    if (pos >= data_bits_) return 0;
    return (static_cast<uint8_t>(data_[pos >> 3]) >> (7 - (pos & 7))) & 1;
  }
  std::string_view data_;
  uint64_t data_bits_;
  uint64_t bit_pos_ = 0;
  uint32_t range_ = 510, offset_ = 0;
};

}  // namespace gvkit::codec
