#include "gvkit/codec/cabac_encoder.hpp"

namespace gvkit::codec {

void CabacEncoder::encode(CabacContext& ctx, int bin) {
  const uint32_t lps = kCabacRangeLps[ctx.state][(range_ >> 6) & 3];
  range_ -= lps;
  if (bin != ctx.mps) {
    low_ += range_;
    range_ = lps;
  }
  cabac_update(ctx, bin);
  renormalize();
}

void CabacEncoder::encode_bypass(int bin) {
  low_ <<= 1;
  if (bin) low_ += range_;
  if (low_ >= 1024) {
    put_bit(1);
    low_ -= 1024;
  } else if (low_ < 512) {
    put_bit(0);
  } else {
    low_ -= 512;
    ++outstanding_;
  }
}

void CabacEncoder::encode_terminate(int bin) {
  range_ -= 2;
  if (bin) {
    low_ += range_;
    range_ = 2;
  }
  renormalize();
}

std::string CabacEncoder::finish() {
  // H.264 9.3.4.5: after the terminating 1 (range = 2, renormalized), emit low's top bits.
  put_bit((low_ >> 9) & 1);
  write_bit((low_ >> 8) & 1);
  write_bit(1);  // the rbsp stop bit keeps the decoder's offset inside the final interval
  while (bit_count_ != 0) write_bit(0);
  std::string out = std::move(bytes_);
  *this = CabacEncoder();
  return out;
}

std::string CabacEncoder::finish_unterminated() {
  // The final interval is [low_, low_ + range_) with range_ >= 256 and low_ + range_ <= 1024 (the
  // renormalization keeps both), so it holds a multiple of 256: take 512 when it lies inside,
  // else that multiple. Its bits 9 and 8 are written (bit 9 resolving the outstanding bits); the
  // decoder, whose 9-bit offset reaches 8 bits further, reads those as zeros past the end.
  const uint32_t v = low_ <= 512 && low_ + range_ > 512 ? 512 : (low_ + 255) / 256 * 256;
  put_bit((v >> 9) & 1);
  write_bit((v >> 8) & 1);
  const auto decoder_bits = static_cast<size_t>(bits_written()) + 8;  // where CabacDecoder stops
  while (bit_count_ != 0) write_bit(0);
  while (!bytes_.empty() && bytes_.back() == 0 && (bytes_.size() - 1) * 8 + 16 >= decoder_bits)
    bytes_.pop_back();
  std::string out = std::move(bytes_);
  *this = CabacEncoder();
  return out;
}

void CabacEncoder::renormalize() {
  while (range_ < 256) {
    if (low_ < 256) {
      put_bit(0);
    } else if (low_ >= 512) {
      low_ -= 512;
      put_bit(1);
    } else {
      low_ -= 256;
      ++outstanding_;
    }
    range_ <<= 1;
    low_ <<= 1;
  }
}

void CabacEncoder::put_bit(int bit) {
  if (first_bit_) {
    first_bit_ = false;
  } else {
    write_bit(bit);
  }
  for (; outstanding_ > 0; --outstanding_) write_bit(1 - bit);
}

void CabacEncoder::write_bit(int bit) {
  current_ = static_cast<uint8_t>((current_ << 1) | bit);
  if (++bit_count_ == 8) {
    bytes_.push_back(static_cast<char>(current_));
    current_ = 0;
    bit_count_ = 0;
  }
}

}  // namespace gvkit::codec
