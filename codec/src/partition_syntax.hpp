#pragma once
// Format 1.7, inter partitions (flags2 bit 5, docs/bitstream.md 4.11): a plain inter macroblock
// of a P plane codes one of H.264's P partitionings (16x16, 16x8, 8x16, 8x8), then per partition
// its ref_idx (with several references) and its motion vector difference. This header holds the
// partition geometry, the mb_type bins (H.264's P mb_type bins 1 and 2, their contexts), the
// per-8x8 motion state the predictors read, and the motion vector predictor of a partition
// (H.264 8.4.1.3). Writer and reader are templated on the coder / decoder.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "gvkit/codec/cabac_context.hpp"

namespace gvkit::codec::detail {

enum PartitionType : uint8_t { kPart16x16 = 0, kPart16x8 = 1, kPart8x16 = 2, kPart8x8 = 3 };
inline constexpr int kPartitionTypeCount = 4;
inline constexpr int kPartitionContexts = 3;

// Number of partitions of a macroblock of type t (1, 2, 2, 4).
inline int partition_count(int t) { return t == kPart16x16 ? 1 : (t == kPart8x8 ? 4 : 2); }

// Partition k of type t in 8x8 units inside the macroblock: top-left (x, y), width w, height h.
struct PartitionRect {
  int x = 0, y = 0, w = 2, h = 2;
};
inline PartitionRect partition_rect(int t, int k) {
  switch (t) {
    case kPart16x8:
      return {0, k, 2, 1};
    case kPart8x16:
      return {k, 0, 1, 2};
    case kPart8x8:
      return {k & 1, k >> 1, 1, 1};
    default:
      return {0, 0, 2, 2};
  }
}
// The partition of type t that covers the 8x8 block (x, y) (0..1 each) of the macroblock.
inline int partition_of_cell(int t, int x, int y) {
  return t == kPart16x8 ? y : (t == kPart8x16 ? x : (t == kPart8x8 ? y * 2 + x : 0));
}

// The partition type bins after is_inter (and skip = 0): bin 1 (context 0) is 0 for 16x16 and
// 8x8, 1 for 16x8 and 8x16; bin 2 (context 1 after a 0, context 2 after a 1) then picks 8x8 /
// 16x16 and 16x8 / 8x16 (H.264's P_L0_16x16 "000", P_8x8 "001", P_L0_L0_16x8 "011",
// P_L0_L0_8x16 "010", without their first bin).
template <class Coder>
void write_partition_type(Coder& coder, CabacContext* ctx, int t) {
  const int b1 = t == kPart16x8 || t == kPart8x16;
  coder.encode(ctx[0], b1);
  coder.encode(ctx[b1 ? 2 : 1], b1 ? t == kPart16x8 : t == kPart8x8);
}
template <class Decoder>
int read_partition_type(Decoder& decoder, CabacContext* ctx) {
  if (decoder.decode(ctx[0])) return decoder.decode(ctx[2]) ? kPart16x8 : kPart8x16;
  return decoder.decode(ctx[1]) ? kPart8x8 : kPart16x16;
}
// The partition type contexts' initial states (the only contexts that do not start
// equiprobable): most plain inter macroblocks are 16x16, so bin 1 starts at pStateIdx 15
// (p(1) = 0.23) and bin 2 after a 0 at 40 (p(8x8) = 0.06); bin 2 after a 1 starts equiprobable.
// With few inter macroblocks per plane the contexts never learn this from equiprobable states.
inline void init_partition_contexts(CabacContext* ctx) {
  ctx[0] = {15, 0};
  ctx[1] = {40, 0};
  ctx[2] = {0, 0};
}
// Encoder: the ideal code length in bits of the partition type bins with the current states.
inline double partition_type_bits(const CabacContext* ctx, int t) {
  const auto cost = [](const CabacContext& c, int bin) {
    return kCabacBitCost[c.state][bin != c.mps ? 1 : 0] * (1.0 / 256.0);
  };
  const int b1 = t == kPart16x8 || t == kPart8x16;
  return cost(ctx[0], b1) + cost(ctx[b1 ? 2 : 1], b1 ? t == kPart16x8 : t == kPart8x8);
}

// The motion of a P plane per 8x8 block (raster order, 2 mbs_x per row) as the partition
// predictors read it: ref -1 for intra blocks (and blocks not coded yet), else the reference
// index and the vector of the partition covering the block (a skip: reference 0 and its vector).
struct PartitionGrid {
  int w8 = 0, h8 = 0;
  std::vector<int8_t> ref;
  std::vector<int16_t> mv_x, mv_y;

  void reset(int mbs_x, int mbs_y) {
    w8 = 2 * mbs_x;
    h8 = 2 * mbs_y;
    ref.assign(static_cast<size_t>(w8) * h8, -1);
    mv_x.assign(ref.size(), 0);
    mv_y.assign(ref.size(), 0);
  }
  size_t index(int x, int y) const { return static_cast<size_t>(y) * w8 + x; }
  // Sets the 8x8 blocks of partition rect r of macroblock (mb_x, mb_y).
  void set(int mb_x, int mb_y, const PartitionRect& r, int ref_idx, int mx, int my) {
    for (int y = 0; y < r.h; ++y)
      for (int x = 0; x < r.w; ++x) {
        const size_t i = index(2 * mb_x + r.x + x, 2 * mb_y + r.y + y);
        ref[i] = static_cast<int8_t>(ref_idx);
        mv_x[i] = static_cast<int16_t>(mx);
        mv_y[i] = static_cast<int16_t>(my);
      }
  }
  void set_macroblock(int mb_x, int mb_y, int ref_idx, int mx, int my) {
    set(mb_x, mb_y, PartitionRect{}, ref_idx, mx, my);
  }
  // Context increment of a partition's ref_idx first bin: how many of the 8x8 blocks left of and
  // above its top-left block (x, y) (plane 8x8 units) are inter with ref_idx > 0.
  int ref_context(int x, int y) const {
    return (x > 0 && ref[index(x - 1, y)] > 0 ? 1 : 0) +
           (y > 0 && ref[index(x, y - 1)] > 0 ? 1 : 0);
  }
};

// Whether the 8x8 block (x, y) (plane 8x8 units) is decoded before partition k of type t of
// macroblock (mb_x, mb_y): inside the plane, and in an earlier macroblock (raster order) or an
// earlier partition of the same one.
inline bool partition_cell_available(const PartitionGrid& g, int x, int y, int mb_x, int mb_y,
                                     int t, int k) {
  if (x < 0 || y < 0 || x >= g.w8) return false;
  const int mx = x / 2, my = y / 2;
  if (my != mb_y) return my < mb_y;
  if (mx != mb_x) return mx < mb_x;
  return partition_of_cell(t, x % 2, y % 2) < k;
}

// Motion vector predictor (H.264 8.4.1.3) of partition k of type t of macroblock (mb_x, mb_y)
// predicting from reference `ref`: neighbours A (left of the top-left block), B (above it),
// C (above the block right of the top-right one; D, above-left, when C is not available).
// 16x8: the upper partition takes B's vector and the lower one A's when that neighbour uses
// the same reference; 8x16: the left one A's, the right one C's; otherwise (and for 8x8) the
// median: A's vector when B and C are unavailable and A is available, else the one neighbour
// with the same reference if exactly one has it, else the component-wise median of A, B, C
// (intra or unavailable neighbours count as vector 0 with no reference).
inline void partition_mv_predictor(const PartitionGrid& g, int mb_x, int mb_y, int t, int k,
                                   int ref, int* px, int* py) {
  const PartitionRect r = partition_rect(t, k);
  const int x0 = 2 * mb_x + r.x, y0 = 2 * mb_y + r.y;
  struct Neighbour {
    bool available = false;
    int ref = -1, mx = 0, my = 0;
  };
  const auto at = [&](int x, int y) {
    Neighbour n;
    if (!partition_cell_available(g, x, y, mb_x, mb_y, t, k)) return n;
    const size_t i = g.index(x, y);
    n.available = true;
    n.ref = g.ref[i];
    if (n.ref >= 0) {
      n.mx = g.mv_x[i];
      n.my = g.mv_y[i];
    }
    return n;
  };
  const Neighbour a = at(x0 - 1, y0), b = at(x0, y0 - 1);
  Neighbour c = at(x0 + r.w, y0 - 1);
  if (!c.available) c = at(x0 - 1, y0 - 1);
  const auto take = [&](const Neighbour& n) {
    *px = n.mx;
    *py = n.my;
  };
  if (t == kPart16x8) {
    const Neighbour& n = k == 0 ? b : a;
    if (n.ref == ref) return take(n);
  } else if (t == kPart8x16) {
    const Neighbour& n = k == 0 ? a : c;
    if (n.ref == ref) return take(n);
  }
  if (!b.available && !c.available && a.available) return take(a);
  const int same = (a.ref == ref) + (b.ref == ref) + (c.ref == ref);
  if (same == 1) return take(a.ref == ref ? a : (b.ref == ref ? b : c));
  const auto median = [](int u, int v, int w) {
    return std::max(std::min(u, v), std::min(std::max(u, v), w));
  };
  *px = median(a.mx, b.mx, c.mx);
  *py = median(a.my, b.my, c.my);
}

}  // namespace gvkit::codec::detail
