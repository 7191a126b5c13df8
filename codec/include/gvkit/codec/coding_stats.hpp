#pragma once
// Where the bits of a coded plane go: per syntax element group, and how many macroblocks took
// each kind of prediction. Filled by the encoder (encode_plane), summed per frame and sequence,
// written by `gvkit encode` into FILE.gvid.stats.json and printed with --verbose.

#include <cstdint>
#include <vector>

namespace gvkit::codec {

// Syntax element groups of the macroblock layer (docs/bitstream.md 4).
enum SyntaxGroup : int {
  kSyntaxMbType,  // is_inter, skip, td_flag, is_i16, is_8x8 (and the motion-shared flag)
  kSyntaxMotion,  // motion vector differences (and reference / partition syntax)
  kSyntaxModes,   // intra and TD prediction modes (4x4, 8x8, 16x16)
  kSyntaxCbp,     // coded block pattern and coded_block_flag
  kSyntaxSigMap,  // significant / last significant coefficient flags
  kSyntaxLevels,  // coefficient magnitudes and signs
  kSyntaxGroupCount
};

// Short name of a group for tables and JSON: "mb_type", "motion", "modes", "cbp", "sig_map",
// "levels".
const char* syntax_group_name(int group);

struct PlaneCodingStats {
  // Bits per group, estimated as the ideal arithmetic-code length of each bin (-log2 of its
  // probability in the context state it was coded with; 1 per bypass bin). They add up to the
  // segment size within the coder's flush (a few bytes per segment).
  double bits[kSyntaxGroupCount] = {};
  int64_t intra_mbs = 0;       // I4x4, I8x8, I16x16
  int64_t inter_mbs = 0;       // inter, not skip, not TD
  int64_t td_mbs = 0;          // inter with temporal-difference prediction
  int64_t td16_mbs = 0;        // format 1.12: TD with one 16x16 mode (of td_mbs)
  int64_t quadratic_mbs = 0;   // format 1.13: I16x16 with the quadratic mode (of intra_mbs)
  int64_t skip_mbs = 0;        // inter skip
  int64_t merge_skip_mbs = 0;  // format 1.11: skips at a neighbour's vector (of skip_mbs)
  int64_t merged_mbs = 0;      // format 1.11: other inter MBs at a neighbour's vector (merged)
  // Format 1.6 (larger transforms): inter and I16x16 macroblocks coded with 8x8 / 16x16.
  int64_t transform8_mbs = 0, transform16_mbs = 0;
  // Y and Z planes with cross-plane prediction (format 1.6): macroblocks that coded a scale,
  // per scale in the order of kCrossScales (-8, -4, -2, -1, 0, 1, 2, 4, 8).
  int64_t cross_scale_mbs[9] = {};
  // P planes with inter partitions (format 1.7): plain inter macroblocks (not skip, shared or
  // TD) per partition type 16x16, 16x8, 8x16, 8x8.
  int64_t partition_mbs[4] = {};

  double total_bits() const;
  PlaneCodingStats& operator+=(const PlaneCodingStats& other);
};

// One coded frame's accounting.
struct FrameCodingStats {
  bool intra = true;
  std::vector<PlaneCodingStats> planes;  // X, Y, Z (, T)
  bool bidirectional = false;            // a B frame (format 1.5; intra is false)
};

}  // namespace gvkit::codec
