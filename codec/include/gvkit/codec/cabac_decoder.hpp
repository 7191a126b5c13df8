#pragma once
// CABAC binary arithmetic decoder (H.264 clause 9.3.3.2), the mirror of CabacEncoder. Reading
// past the end of the data yields zero bits (never out of bounds); overrun() tells whether that
// went further than a correct stream ever needs, which callers report as corrupt data.
//
// The decoding engine is inline (it runs once per bin). The 9-bit codIOffset is kept together
// with the stream bits read ahead of it: value_ = codIOffset << ahead_ | the next ahead_ bits,
// so that renormalizing by n bits is ahead_ -= n, and the bytes are loaded four at a time.
// (Data whose first 9 bits are 510 or 511, which H.264 rules out, decodes to some bins, as any
// other damaged data does.)

#include <cstdint>
#include <cstring>
#include <string_view>

#include "gvkit/codec/cabac_context.hpp"

namespace gvkit::codec {

class CabacDecoder {
 public:
  explicit CabacDecoder(std::string_view data)
      : data_(data), data_bits_(static_cast<uint64_t>(data.size()) * 8) {
    refill();
    ahead_ -= 9;  // codIOffset = the first 9 bits
  }

  // Without branches on the bin (it is unpredictable): masks select the LPS's values.
  int decode(CabacContext& ctx) {
    const uint32_t lps = kCabacRangeLps[ctx.state][(range_ >> 6) & 3];
    range_ -= lps;
    const uint64_t scaled = static_cast<uint64_t>(range_) << ahead_;
    const uint32_t is_lps = value_ >= scaled ? 1u : 0u;  // codIOffset >= codIRange
    const uint64_t mask = 0 - static_cast<uint64_t>(is_lps);
    value_ -= scaled & mask;
    range_ ^= (range_ ^ lps) & static_cast<uint32_t>(mask);
    const int bin = ctx.mps ^ static_cast<int>(is_lps);
    cabac_transition(ctx, static_cast<int>(is_lps));
    renormalize();
    return bin;
  }

  int decode_bypass() {
    if (ahead_ < 1) refill();
    --ahead_;  // codIOffset = codIOffset << 1 | the next bit
    const uint64_t scaled = static_cast<uint64_t>(range_) << ahead_;
    if (value_ >= scaled) {
      value_ -= scaled;
      return 1;
    }
    return 0;
  }

  int decode_terminate() {
    range_ -= 2;
    if (value_ >= static_cast<uint64_t>(range_) << ahead_) return 1;
    renormalize();
    return 0;
  }

  // True when more than 16 bits past the end of the data were consumed.
  bool overrun() const { return consumed_bits() > data_bits_ + 16; }

 private:
  // Bits taken into codIOffset so far (9 at the start, one per renormalization shift).
  uint64_t consumed_bits() const { return static_cast<uint64_t>(byte_pos_) * 8 - ahead_; }

  // Four more bytes behind value_ (zeros past the end of the data). value_ stays below
  // 2^(9 + ahead_) <= 2^47.
  void refill() {
    uint32_t word = 0;
    if (byte_pos_ + 4 <= data_.size()) {
      uint8_t b[4];
      std::memcpy(b, data_.data() + byte_pos_, 4);
      word = static_cast<uint32_t>(b[0]) << 24 | static_cast<uint32_t>(b[1]) << 16 |
             static_cast<uint32_t>(b[2]) << 8 | b[3];
    } else {
      for (size_t k = 0; k < 4; ++k) {
        const size_t at = byte_pos_ + k;
        word = word << 8 | (at < data_.size() ? static_cast<uint8_t>(data_[at]) : 0u);
      }
    }
    byte_pos_ += 4;
    value_ = value_ << 32 | word;
    ahead_ += 32;
  }

  // codIRange is 2..510 here, so n is 0..7 (0 from 256 on).
  void renormalize() {
    const int n = __builtin_clz(range_) - 23;
    range_ <<= n;
    if (ahead_ < n) refill();
    ahead_ -= n;
  }

  std::string_view data_;
  uint64_t data_bits_;
  uint64_t value_ = 0;  // codIOffset << ahead_ | the bits read ahead of it
  int ahead_ = 0;
  size_t byte_pos_ = 0;  // bytes loaded into value_ (past the end: zeros)
  uint32_t range_ = 510;
};

// The plain decoding engine (bit by bit, as clause 9.3.3.2 writes it), kept to check
// CabacDecoder: the same bins, context states and overrun() on any data whose first 9 bits
// are below 510.
class CabacDecoderReference {
 public:
  explicit CabacDecoderReference(std::string_view data);
  int decode(CabacContext& ctx);
  int decode_bypass();
  int decode_terminate();
  bool overrun() const { return bit_pos_ > data_bits_ + 16; }

 private:
  uint32_t read_bit();
  std::string_view data_;
  uint64_t data_bits_, bit_pos_ = 0;
  uint32_t range_ = 510, offset_ = 0;
};

}  // namespace gvkit::codec
