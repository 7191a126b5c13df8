#pragma once
// The boundary strengths of a coded plane's edges (format 1.8, docs/bitstream.md 4.12), from
// the macroblock state that the encoder and the decoder both keep (PlaneState).

#include <cstdlib>

#include "gvkit/codec/deblocking.hpp"
#include "macroblock_syntax.hpp"

namespace gvkit::codec::detail {

// Whether macroblock m is intra or TD-predicted (2 at its macroblock edges).
inline bool intra_like(const PlaneState& st, size_t m) {
  return st.mb_type[m] != kMbInter || st.td[m];
}

// Whether two vectors differ by `unit` (a whole sample in the vectors' units) or more in a
// component.
inline bool vectors_differ(int unit, int x0, int y0, int x1, int y1) {
  return std::abs(x0 - x1) >= unit || std::abs(y0 - y1) >= unit;
}

// Strength of an edge between inter macroblocks ma != mb (neither intra nor TD-predicted) of a
// plane without inter partitions (or a B plane), where neither 4x4 block has coded levels: 1
// where either macroblock is not a skip or their motion differs (reference, lists, or a vector
// component by a whole sample or more), else 0. The same for all four blocks along the edge.
inline int inter_edge_strength(const PlaneState& st, bool quarter_pel, size_t ma, size_t mb) {
  if (!st.skip[ma] || !st.skip[mb]) return 1;
  const int unit = quarter_pel ? 4 : 1;  // a whole sample
  if (st.bidirectional) {
    if (st.lists[ma] != st.lists[mb]) return 1;
    if ((st.lists[ma] & 1) &&
        vectors_differ(unit, st.mv_x[ma], st.mv_y[ma], st.mv_x[mb], st.mv_y[mb]))
      return 1;
    if ((st.lists[ma] & 2) &&
        vectors_differ(unit, st.mv_x1[ma], st.mv_y1[ma], st.mv_x1[mb], st.mv_y1[mb]))
      return 1;
    return 0;
  }
  if (st.ref_idx[ma] != st.ref_idx[mb]) return 1;
  return vectors_differ(unit, st.mv_x[ma], st.mv_y[ma], st.mv_x[mb], st.mv_y[mb]) ? 1 : 0;
}

// Strength of the edge between 4x4 blocks a and b (block coordinates; a left of or above b) of
// a plane whose vectors are in quarter samples when quarter_pel:
// - 2 at a macroblock edge where either side is intra or TD-predicted, and inside such a
//   macroblock at its transform blocks' edges (I16x16: only where a side has coded levels);
// - 1 at a transform block edge where either block has coded levels (coded_block_flag), at a
//   macroblock edge where either side is a non-skip inter macroblock, or where the blocks'
//   motion differs (reference, lists, or a vector component by a whole sample or more);
// - else 0. No edge lies inside a 16x16 transform but the edges of inter partitions.
inline int edge_strength(const PlaneState& st, bool quarter_pel, int ax, int ay, int bx, int by) {
  // (Block coordinates are >= 0: shifts, not signed divisions.)
  const size_t ma = static_cast<size_t>(ay >> 2) * st.mbs_x + (ax >> 2),
               mb = static_cast<size_t>(by >> 2) * st.mbs_x + (bx >> 2);
  const bool internal = ma == mb;
  const bool transform_edge = !internal || st.transform[ma] != 2;
  const int w4 = st.w4();
  const bool coded =
      st.cbf4[static_cast<size_t>(ay) * w4 + ax] || st.cbf4[static_cast<size_t>(by) * w4 + bx];
  if (intra_like(st, ma) || intra_like(st, mb)) {
    if (!internal) return 2;
    if (!transform_edge) return 0;
    return st.mb_type[ma] == kMbI16x16 && !coded ? 0 : 2;
  }
  if (transform_edge && coded) return 1;
  if (st.partitions && !st.bidirectional) {  // format 1.7: motion per 8x8 block
    if (!internal && (!st.skip[ma] || !st.skip[mb])) return 1;
    const size_t ga = st.grid.index(ax >> 1, ay >> 1), gb = st.grid.index(bx >> 1, by >> 1);
    if (st.grid.ref[ga] != st.grid.ref[gb]) return 1;
    return vectors_differ(quarter_pel ? 4 : 1, st.grid.mv_x[ga], st.grid.mv_y[ga], st.grid.mv_x[gb],
                          st.grid.mv_y[gb])
               ? 1
               : 0;
  }
  if (internal) return 0;
  return inter_edge_strength(st, quarter_pel, ma, mb);
}

// The strengths of every edge on the plane's 8x8 grid, edge by edge (the plain form, kept to
// check deblocking_strengths: the same strengths for any state).
inline void deblocking_strengths_reference(const PlaneState& st, bool quarter_pel,
                                           DeblockingStrengths& out) {
  const int w4 = st.w4(), h4 = st.mbs_y * 4;
  out.reset(w4, h4);
  for (int gy = 0; gy < h4; ++gy) {
    uint8_t* vertical = &out.vertical[static_cast<size_t>(gy) * w4];
    for (int gx = 2; gx < w4; gx += 2)
      vertical[gx] = static_cast<uint8_t>(edge_strength(st, quarter_pel, gx - 1, gy, gx, gy));
    if (gy % 2 != 0 || gy == 0) continue;
    uint8_t* horizontal = &out.horizontal[static_cast<size_t>(gy) * w4];
    for (int gx = 0; gx < w4; ++gx)
      horizontal[gx] = static_cast<uint8_t>(edge_strength(st, quarter_pel, gx, gy - 1, gx, gy));
  }
}

// The strengths of every edge on the plane's 8x8 grid, macroblock by macroblock: its left and
// top edges and its two inner ones. Where an intra or TD-predicted macroblock is on either side
// (most macroblocks of a geometry video) the strength follows from the macroblock's type,
// transform and coded-block flags alone (edge_strength's first case); between inter macroblocks
// without partitions from the coded-block flags and one inter_edge_strength per macroblock
// edge; the edges of partitioned planes are edge_strength's.
inline void deblocking_strengths(const PlaneState& st, bool quarter_pel, DeblockingStrengths& out) {
  const int w4 = st.w4(), h4 = st.mbs_y * 4;
  out.reset(w4, h4);
  const auto coded = [&](int ax, int ay, int bx, int by) {
    return st.cbf4[static_cast<size_t>(ay) * w4 + ax] || st.cbf4[static_cast<size_t>(by) * w4 + bx];
  };
  const bool per_block_motion = st.partitions && !st.bidirectional;
  for (int my = 0; my < st.mbs_y; ++my)
    for (int mx = 0; mx < st.mbs_x; ++mx) {
      const size_t m = static_cast<size_t>(my) * st.mbs_x + mx;
      const bool intra = intra_like(st, m);
      const bool generic = !intra && per_block_motion;
      // An edge with the macroblock on the left (n = m - 1) or above (n = m - mbs_x): 2 next to
      // an intra-like one (kNextToIntra), edge_strength per block with partitions (kPerBlock),
      // else 1 where coded and otherwise the pair's inter strength (returned here).
      constexpr int kNextToIntra = -2, kPerBlock = -1;
      const auto outer = [&](size_t n) {
        return intra || intra_like(st, n) ? kNextToIntra
               : generic                  ? kPerBlock
                                          : inter_edge_strength(st, quarter_pel, n, m);
      };
      // Inside: intra-like macroblocks 0 within a 16x16 transform, I16x16 only where coded,
      // else 2; inter ones (no partitions) 1 where coded at a transform edge, else 0.
      const bool inner_none = st.transform[m] == 2;
      const auto inner = [&](int ax, int ay, int bx, int by) -> uint8_t {
        if (generic) return static_cast<uint8_t>(edge_strength(st, quarter_pel, ax, ay, bx, by));
        if (inner_none) return 0;
        if (intra && st.mb_type[m] != kMbI16x16) return 2;
        return coded(ax, ay, bx, by) ? (intra ? 2 : 1) : 0;
      };
      const auto across = [&](int pair, int ax, int ay, int bx, int by) -> uint8_t {
        if (pair == kNextToIntra) return 2;
        if (pair == kPerBlock)
          return static_cast<uint8_t>(edge_strength(st, quarter_pel, ax, ay, bx, by));
        return coded(ax, ay, bx, by) ? 1 : static_cast<uint8_t>(pair);
      };
      const int gx0 = mx * 4, gy0 = my * 4;
      const int left = mx > 0 ? outer(m - 1) : 0, top = my > 0 ? outer(m - st.mbs_x) : 0;
      for (int gy = gy0; gy < gy0 + 4; ++gy) {
        uint8_t* vertical = &out.vertical[static_cast<size_t>(gy) * w4];
        if (mx > 0) vertical[gx0] = across(left, gx0 - 1, gy, gx0, gy);
        vertical[gx0 + 2] = inner(gx0 + 1, gy, gx0 + 2, gy);
      }
      for (int gy = my > 0 ? gy0 : gy0 + 2; gy < gy0 + 4; gy += 2) {
        uint8_t* horizontal = &out.horizontal[static_cast<size_t>(gy) * w4];
        for (int gx = gx0; gx < gx0 + 4; ++gx)
          horizontal[gx] = gy == gy0 ? across(top, gx, gy - 1, gx, gy) : inner(gx, gy - 1, gx, gy);
      }
    }
}

// The deblocking of a coded plane after its last macroblock (encoder and decoder), when
// p.deblocking is on in a lossy plane.
inline void deblock_coded_plane(SamplePlane& plane, const PlaneState& st,
                                const PlaneCodingParams& p) {
  if (!p.deblocking || p.lossless) return;
  DeblockingStrengths strengths;
  deblocking_strengths(st, p.subpel != 0, strengths);
  deblock_plane(plane, strengths, p.qp_prime, p.bit_depth, p.deblock);
}

}  // namespace gvkit::codec::detail
