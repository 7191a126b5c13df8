#pragma once
// Cross-plane contexts (format 1.7, flags2 bit 4, docs/bitstream.md 4.10): the context
// increments a Y or Z macroblock adds to those of its own neighbours, from the co-located
// decisions of the X plane. Every function returns 0 when x is null (the tool off, the X plane
// itself, texture), so the contexts are then those of format 1.6.

#include <cstddef>
#include <cstdint>

#include "gvkit/codec/cross_plane_contexts.hpp"

namespace gvkit::codec::detail {

// Macroblock flags whose contexts count the left and top neighbours (0..2): + 3 when the
// co-located X macroblock (raster index mb) has the property.
inline int x_skip_increment(const CrossPlaneDecisions* x, size_t mb) {
  return x && x->skip[mb] ? 3 : 0;
}
inline int x_inter_increment(const CrossPlaneDecisions* x, size_t mb) {
  return x && x->inter(mb) ? 3 : 0;
}
inline int x_type_increment(const CrossPlaneDecisions* x, size_t mb, uint8_t type) {
  return x && x->mb_type[mb] == type ? 3 : 0;
}
inline int x_td_increment(const CrossPlaneDecisions* x, size_t mb) {
  return x && x->td[mb] ? 3 : 0;
}
// transform_size bin 0 (code 1) and bin 1 (code 2): X's transform code at least `code`.
inline int x_transform_increment(const CrossPlaneDecisions* x, size_t mb, int code) {
  return x && x->transform[mb] >= code ? 3 : 0;
}
// The cbp bit of the 8x8 block (cx, cy) and the coded_block_flag of the 4x4 block (gx, gy),
// whose contexts are left + 2 top (0..3): + 4 when X's block at the same place is coded.
inline int x_cbp_increment(const CrossPlaneDecisions* x, int cx, int cy) {
  return x && x->cbp8[static_cast<size_t>(cy) * 2 * x->mbs_x + cx] ? 4 : 0;
}
inline int x_cbf_increment(const CrossPlaneDecisions* x, int gx, int gy) {
  return x && x->cbf4[static_cast<size_t>(gy) * 4 * x->mbs_x + gx] ? 4 : 0;
}

}  // namespace gvkit::codec::detail
