#pragma once
// Format 1.6, multiple reference frames (docs/bitstream.md 4.7): the ref_idx syntax element of
// an inter macroblock of a P plane with ref_count > 1 references. Truncated unary with cMax =
// ref_count - 1 (bin i = 1 means ref_idx > i); bin 0 uses context ctx[inc], inc = the number of
// the left and top macroblocks with ref_idx > 0 (0..2), bin 1 ctx[3], later bins ctx[4] (H.264's
// ref_idx binarization and contexts). The writer is templated on the coder (CabacEncoder,
// CabacBitCounter, StatsCoder), the reader on the decoder.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "gvkit/codec/cabac_context.hpp"

namespace gvkit::codec::detail {

inline constexpr int kRefIdxContexts = 5;

// inc of ref_idx's first bin for macroblock (mb_x, mb_y): ref_idx holds one entry per
// macroblock of the plane (raster order, mbs_x per row; 0 for intra macroblocks and skips).
inline int ref_idx_context(const std::vector<uint8_t>& ref_idx, int mbs_x, int mb_x, int mb_y) {
  const size_t i = static_cast<size_t>(mb_y) * mbs_x + mb_x;
  return (mb_x > 0 && ref_idx[i - 1] > 0 ? 1 : 0) + (mb_y > 0 && ref_idx[i - mbs_x] > 0 ? 1 : 0);
}

// The context index of bin `bin` of ref_idx.
inline int ref_idx_bin_context(int inc, int bin) { return bin == 0 ? inc : (bin == 1 ? 3 : 4); }

// Writes ref_idx (0 .. ref_count - 1; contract) with the contexts ctx[0..4].
template <class Coder>
void write_ref_idx(Coder& coder, CabacContext* ctx, int inc, int ref_idx, int ref_count) {
  for (int b = 0; b < ref_count - 1; ++b) {
    const int bin = b < ref_idx ? 1 : 0;
    coder.encode(ctx[ref_idx_bin_context(inc, b)], bin);
    if (!bin) break;
  }
}

// Reads ref_idx: at most ref_count - 1 bins, so every bin string is a valid index.
template <class Decoder>
int read_ref_idx(Decoder& decoder, CabacContext* ctx, int inc, int ref_count) {
  int v = 0;
  while (v < ref_count - 1 && decoder.decode(ctx[ref_idx_bin_context(inc, v)])) ++v;
  return v;
}

// Encoder: the ideal code length in bits of ref_idx with the contexts' current states.
inline double ref_idx_bits(const CabacContext* ctx, int inc, int ref_idx, int ref_count) {
  double bits = 0;
  for (int b = 0; b < ref_count - 1; ++b) {
    const CabacContext& c = ctx[ref_idx_bin_context(inc, b)];
    const int bin = b < ref_idx ? 1 : 0;
    bits += kCabacBitCost[c.state][bin != c.mps ? 1 : 0] * (1.0 / 256.0);
    if (!bin) break;
  }
  return bits;
}

}  // namespace gvkit::codec::detail
