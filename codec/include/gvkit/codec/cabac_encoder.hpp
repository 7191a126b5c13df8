#pragma once
// CABAC binary arithmetic encoder (H.264 clause 9.3.4): context-coded decisions, bypass bins and
// the terminating bin, writing bytes. CabacBitCounter has the same interface and only adds up
// the estimated cost of the bins, for rate-distortion decisions.

#include <cstdint>
#include <string>

#include "gvkit/codec/cabac_context.hpp"

namespace gvkit::codec {

class CabacEncoder {
 public:
  void encode(CabacContext& ctx, int bin);
  void encode_bypass(int bin);
  // Terminating bin; after encode_terminate(1) call finish().
  void encode_terminate(int bin);
  // Flushes the coder (after a terminating 1) and returns the bytes; the encoder is then reset.
  std::string finish();
  // Flushes the coder after its last bin, with no terminating bin (format 1.10), in the fewest
  // bytes: the value of the final interval with the most trailing zeros, its trailing zero bytes
  // dropped as long as CabacDecoder, which reads zeros past the end, stays within its 16-bit
  // allowance (CabacDecoder::overrun). About a byte less than encode_terminate(1) + finish(); a
  // segment may become empty. The decoder must know where the bins end. The encoder is reset.
  std::string finish_unterminated();
  // Bits written so far (approximate: excludes outstanding bits and the flush).
  int64_t bits_written() const { return static_cast<int64_t>(bytes_.size()) * 8 + bit_count_; }

 private:
  void renormalize();
  void put_bit(int bit);
  void write_bit(int bit);

  uint32_t low_ = 0, range_ = 510;
  int outstanding_ = 0;
  bool first_bit_ = true;
  uint8_t current_ = 0;
  int bit_count_ = 0;
  std::string bytes_;
};

// Adds up -log2(p) of each bin (in 1/256 bit) and adapts the contexts like the encoder would.
class CabacBitCounter {
 public:
  void encode(CabacContext& ctx, int bin) {
    const int is_lps = bin != ctx.mps ? 1 : 0;
    cost_ += kCabacBitCost[ctx.state][is_lps];
    cabac_transition(ctx, is_lps);
  }
  void encode_bypass(int) { cost_ += 256; }
  void encode_terminate(int) {}
  int64_t cost_256() const { return cost_; }  // in 1/256 bit
  double bits() const { return cost_ / 256.0; }

 private:
  int64_t cost_ = 0;
};

}  // namespace gvkit::codec
