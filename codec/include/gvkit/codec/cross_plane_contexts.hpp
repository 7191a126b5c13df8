#pragma once
// Cross-plane contexts (format 1.7, flags2 bit 4, docs/bitstream.md 4.10): the Y and Z planes of
// a frame select the contexts of their macroblock flags (skip, is_inter, shared_mv, td_flag,
// is_i16, is_8x8, transform_size) and of their coded block pattern and coded_block_flag bins by
// the decision the X plane took at the same place as well as by their own neighbours. X is
// coded first; its decisions are decoder-side information, so the tool adds no syntax element.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace gvkit::codec {

// The decisions of a coded plane that the context selection of the other planes looks at, per
// macroblock in raster order (mbs_x x mbs_y), per 8x8 block (2 mbs_x x 2 mbs_y, raster order)
// and per 4x4 block (4 mbs_x x 4 mbs_y, raster order). Empty (mbs_x == 0) until a plane is
// recorded into it.
struct CrossPlaneDecisions {
  int mbs_x = 0, mbs_y = 0;
  std::vector<uint8_t> mb_type;    // 0: I4x4, 1: I8x8, 2: I16x16, 3: inter (incl. skip and TD)
  std::vector<uint8_t> skip;       // 1: skip
  std::vector<uint8_t> td;         // 1: inter with temporal-difference prediction
  std::vector<uint8_t> transform;  // residual transform: 0 = 4x4 (or none), 1 = 8x8, 2 = 16x16
  std::vector<uint8_t> cbp8;       // per 8x8 block: coded_block_pattern bit (0 for a skip)
  std::vector<uint8_t> cbf4;       // per 4x4 block: coded_block_flag (1 in coded 8x8 / 16x16)

  bool inter(size_t mb) const { return mb_type[mb] == 3; }
};

}  // namespace gvkit::codec
