#include "gvkit/codec/cabac_decoder.hpp"

namespace gvkit::codec {

CabacDecoder::CabacDecoder(std::string_view data)
    : data_(data), data_bits_(static_cast<uint64_t>(data.size()) * 8) {
  offset_ = read_bits(9);
}

int CabacDecoder::decode(CabacContext& ctx) {
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
  renormalize();
  return bin;
}

int CabacDecoder::decode_bypass() {
  offset_ = (offset_ << 1) | read_bits(1);
  if (offset_ >= range_) {
    offset_ -= range_;
    return 1;
  }
  return 0;
}

int CabacDecoder::decode_terminate() {
  range_ -= 2;
  if (offset_ >= range_) return 1;
  renormalize();
  return 0;
}

}  // namespace gvkit::codec
