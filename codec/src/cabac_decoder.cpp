// CabacDecoder is inline (cabac_decoder.hpp); this is its plain reference.
#include "gvkit/codec/cabac_decoder.hpp"

namespace gvkit::codec {

CabacDecoderReference::CabacDecoderReference(std::string_view data)
    : data_(data), data_bits_(static_cast<uint64_t>(data.size()) * 8) {
  for (int i = 0; i < 9; ++i) offset_ = (offset_ << 1) | read_bit();
}

uint32_t CabacDecoderReference::read_bit() {
  const uint64_t byte = bit_pos_ / 8;
  const uint32_t bit =
      byte < data_.size() ? (static_cast<uint8_t>(data_[byte]) >> (7 - bit_pos_ % 8)) & 1u : 0u;
  ++bit_pos_;
  return bit;
}

int CabacDecoderReference::decode(CabacContext& ctx) {
  const uint32_t lps = kCabacRangeLps[ctx.state][(range_ >> 6) & 3];
  range_ -= lps;
  int bin;
  if (offset_ >= range_) {
    bin = 1 - ctx.mps;
    offset_ -= range_;
    range_ = lps;
  } else {
    bin = ctx.mps;
  }
  cabac_update(ctx, bin);
  while (range_ < 256) {
    range_ <<= 1;
    offset_ = (offset_ << 1) | read_bit();
  }
  return bin;
}

int CabacDecoderReference::decode_bypass() {
  offset_ = (offset_ << 1) | read_bit();
  if (offset_ >= range_) {
    offset_ -= range_;
    return 1;
  }
  return 0;
}

int CabacDecoderReference::decode_terminate() {
  range_ -= 2;
  if (offset_ >= range_) return 1;
  while (range_ < 256) {
    range_ <<= 1;
    offset_ = (offset_ << 1) | read_bit();
  }
  return 0;
}

}  // namespace gvkit::codec
