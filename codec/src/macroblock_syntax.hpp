#pragma once
// Shared pieces of the macroblock layer: contexts, per-plane neighbour state, block geometry and
// the syntax writer (templated on CabacEncoder or CabacBitCounter). The reader mirrors
// write_macroblock in plane_decoder.cpp.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <type_traits>
#include <vector>

#include "cross_plane_syntax.hpp"
#include "gvkit/codec/cabac_context.hpp"
#include "gvkit/codec/cabac_encoder.hpp"
#include "gvkit/codec/coding_stats.hpp"
#include "gvkit/codec/cross_plane.hpp"
#include "gvkit/codec/cross_plane_contexts.hpp"
#include "gvkit/codec/intra_prediction.hpp"
#include "gvkit/codec/inverse_residual.hpp"
#include "gvkit/codec/motion_compensation.hpp"
#include "gvkit/codec/plane_coding.hpp"
#include "gvkit/codec/quadratic_intra.hpp"
#include "gvkit/codec/reconstruction_store.hpp"
#include "gvkit/codec/transform.hpp"
#include "gvkit/codec/transform16x16.hpp"
#include "partition_syntax.hpp"
#include "reference_index_syntax.hpp"

namespace gvkit::codec::detail {

enum MbType : uint8_t { kMbI4x4 = 0, kMbI8x8 = 1, kMbI16x16 = 2, kMbInter = 3 };

constexpr int kMaxMotion = 64;  // |motion vector component| in samples
// Format 1.11 (merge): the most candidate vectors a P macroblock may take besides the predictor
// (2, 3 and 4 measured on the ICT face: -10.45, -12.11 and -12.98 % BD-rate in the slow preset).
constexpr int kMergeCandidates = 4;
// Exp-Golomb escape of a motion vector difference: at most this many leading ones (whole-sample
// differences reach 128, quarter-sample ones 512).
inline int max_mvd_escape(bool quarter_pel) { return quarter_pel ? 10 : 8; }

constexpr int kLevelPrefixMax = 14;  // unary part of |level| - 1, then Exp-Golomb (k = 0)
constexpr int kMaxAbsLevel = 1 << 24;

struct ContextSet {
  CabacContext is_i16[3];
  CabacContext is_8x8[3];
  CabacContext i16_mode[2];
  CabacContext prev_mode_flag[1];
  CabacContext rem_mode[1];
  CabacContext cbp[4];
  CabacContext cbf[4];
  // Residual categories: 0 = 4x4, 1 = 8x8, 2 = 16x16 (format 1.6, larger transforms).
  CabacContext sig[3][16];
  CabacContext last[3][16];
  CabacContext level[3][10];
  CabacContext is_inter[3];
  CabacContext skip[3];
  CabacContext mvd_zero[2];
  CabacContext td_flag[3];
  CabacContext shared_mv[3];    // format 1.4: take the co-located first-plane vector
  CabacContext shared_skip[2];  // ... then skip, by whether the co-located MB is a skip
  // Format 1.5, B planes: direct (bin 0), else bi (bin 1), else L1 (bin 2).
  CabacContext b_pred[3];
  // Format 1.6, P planes with several references: ref_idx as truncated unary; bin 0 by the
  // left and top macroblocks' ref_idx > 0 (0..2), bin 1 context 3, later bins context 4.
  CabacContext ref_idx[kRefIdxContexts];
  // Format 1.6 (larger transforms): bin 0 "larger than 4x4", bin 1 "16x16", by neighbours.
  CabacContext transform_size[2][3];
  // Format 1.6, Y and Z planes: cross-plane scale, log2_res_scale_abs_plus1 bins and sign.
  CabacContext cross_scale[4];
  CabacContext cross_sign[1];
  // Format 1.7, inter partitions: the partition type bins (partition_syntax.hpp).
  CabacContext partition[kPartitionContexts];
  // Format 1.11, merge (P planes): merge_idx of a skip (0: the predictor) and of another 16x16
  // inter macroblock (0: not merged) as truncated unary, bin k in context k.
  CabacContext merge_idx[kMergeCandidates];
  CabacContext merge_inter[kMergeCandidates];
  // Format 1.12, TD16 (P planes): a TD macroblock's td16 bin (by the left and top macroblocks
  // being TD16) and the two bins of its 16x16 mode.
  CabacContext td16[3];
  CabacContext td16_mode[2];
  // Format 1.13, quadratic intra: whether an I16x16 macroblock takes the quadratic mode.
  CabacContext i16_quadratic[1];
  CabacContext td16_quadratic[1];  // ... and a TD16 macroblock
  // (Format 1.7, cross-plane contexts: Y and Z inherit every context declared above
  // adaptive_levels, so new contexts go above it.)
  // Adaptive level coding (lossless streams): |level| - 2 as bypass Exp-Golomb with an order
  // that follows a running mean of the magnitudes per category (16 x the mean).
  bool adaptive_levels = false;
  uint32_t level_mean16[3] = {};
};

// ---- Cross-plane contexts (format 1.7, docs/bitstream.md 4.10) ----
// The X plane's final context states (every CabacContext of ContextSet, which come first and lie
// contiguously: two bytes of alignment 1 each, in declaration order) and level means are the
// initial ones of the Y and Z planes.
inline constexpr size_t kContextSetContexts =
    offsetof(ContextSet, adaptive_levels) / sizeof(CabacContext);
static_assert(std::is_standard_layout_v<ContextSet> && alignof(CabacContext) == 1 &&
              sizeof(CabacContext) == 2 && offsetof(ContextSet, is_i16) == 0);
inline void export_context_states(const ContextSet& ctx, CrossPlaneContextStates& out) {
  out.contexts.resize(kContextSetContexts);
  std::memcpy(static_cast<void*>(out.contexts.data()), &ctx,
              kContextSetContexts * sizeof(CabacContext));
  std::copy(ctx.level_mean16, ctx.level_mean16 + 3, out.level_mean16);
}
// `in` must hold kContextSetContexts contexts (contract).
inline void import_context_states(const CrossPlaneContextStates& in, ContextSet& ctx) {
  GVKIT_CHECK(in.contexts.size() == kContextSetContexts);
  std::memcpy(static_cast<void*>(&ctx), in.contexts.data(),
              kContextSetContexts * sizeof(CabacContext));
  std::copy(in.level_mean16, in.level_mean16 + 3, ctx.level_mean16);
}
// ---- end of cross-plane contexts ----

// A CabacEncoder that also adds each bin's ideal code length to the current syntax group of a
// PlaneCodingStats (the writer names the group with set_group before each element).
class StatsCoder {
 public:
  StatsCoder(CabacEncoder& encoder, PlaneCodingStats& stats) : enc_(encoder), stats_(stats) {}
  void encode(CabacContext& ctx, int bin) {
    stats_.bits[group_] += kCabacBitCost[ctx.state][bin != ctx.mps ? 1 : 0] * (1.0 / 256.0);
    enc_.encode(ctx, bin);
  }
  void encode_bypass(int bin) {
    stats_.bits[group_] += 1.0;
    enc_.encode_bypass(bin);
  }
  void set_group(int group) { group_ = group; }

 private:
  CabacEncoder& enc_;
  PlaneCodingStats& stats_;
  int group_ = kSyntaxMbType;
};

// Names the syntax group of the bins that follow (a no-op for coders without accounting).
template <class Coder>
inline void set_group(Coder& coder, int group) {
  if constexpr (requires { coder.set_group(group); }) coder.set_group(group);
}

// The largest k <= 20 with 2^k <= mean16 / 16 (0 below 2): floor(log2(mean)), capped.
inline int adaptive_order(uint32_t mean16) {
  const uint32_t mean = mean16 >> 4;
  return mean < 2 ? 0 : std::min(20, 31 - __builtin_clz(mean));
}

inline void update_level_mean(uint32_t& mean16, uint32_t abs_minus1) {
  mean16 += std::min<uint32_t>(abs_minus1, 1u << 24) - (mean16 >> 4);
}

// Raster (x, y) in 4x4 units inside a macroblock of the z-order block index 0..15.
inline int block_x(int idx) { return ((idx >> 2) & 1) * 2 + (idx & 1); }
inline int block_y(int idx) { return ((idx >> 3) & 1) * 2 + ((idx >> 1) & 1); }
inline int zorder_index(int bx, int by) {
  return ((by >> 1) * 2 + (bx >> 1)) * 4 + (by & 1) * 2 + (bx & 1);
}

// Everything coded so far in a plane that later macroblocks' contexts depend on.
struct PlaneState {
  int mbs_x = 0, mbs_y = 0;
  std::vector<uint8_t> mb_type;     // per macroblock
  std::vector<int8_t> mode4;        // per 4x4 block: prediction mode for the most probable mode
  std::vector<uint8_t> cbf4;        // per 4x4 block: coded_block_flag (1 for coded 8x8 blocks)
  std::vector<uint8_t> cbp8;        // per 8x8 block: coded_block_pattern bit
  bool predicted = false;           // a P plane: macroblocks may be inter
  std::vector<uint8_t> skip;        // per macroblock (inter, no motion difference, no residual)
  std::vector<int16_t> mv_x, mv_y;  // per macroblock, inter only (units of the plane)
  std::vector<uint8_t> td;          // per macroblock: inter with temporal-difference prediction
  std::vector<uint8_t> td16;        // per macroblock: TD with a 16x16 mode (format 1.12)
  std::vector<uint8_t> shared;      // per macroblock: took the co-located first-plane vector
  std::vector<uint8_t> ref_idx;     // per macroblock: reference of an inter MB (format 1.6), else 0
  const MotionField* colocated = nullptr;  // the first plane's motion (shared motion), or null
  bool merge = false;  // format 1.11, P planes: a macroblock may take a neighbour's vector
  // Format 1.11: the plane's motion in reference 0 (merge's co-located candidate), or null.
  const MotionField* reference_motion = nullptr;
  // B planes (format 1.5): inter macroblocks predict from list 0 (the anchor before), list 1
  // (the anchor after) or both; mv_x / mv_y are the list 0 vectors.
  bool bidirectional = false;
  std::vector<uint8_t> lists;         // per macroblock: bit 0 uses list 0, bit 1 list 1
  std::vector<int16_t> mv_x1, mv_y1;  // per macroblock: list 1 vectors
  // Per macroblock, format 1.6: the residual's transform (0: 4x4, 1: 8x8 or I8x8, 2: 16x16).
  std::vector<uint8_t> transform;
  // Format 1.6, Y and Z planes: the residual predicted from (X's), or null (tool off).
  const CrossPlaneResidual* cross = nullptr;
  // Format 1.7 (inter partitions), P planes: motion per 8x8 block, which the vector predictors
  // and ref_idx contexts read instead of the per-macroblock arrays (enable_partitions).
  bool partitions = false;
  PartitionGrid grid;
  void enable_partitions() {
    partitions = true;
    grid.reset(mbs_x, mbs_y);
  }
  // Context increment of the first ref_idx bin of a 16x16 macroblock (format 1.6; with
  // partitions from the 8x8 blocks next to its top-left one).
  int ref_context(int mb_x, int mb_y) const {
    return partitions ? grid.ref_context(2 * mb_x, 2 * mb_y)
                      : ref_idx_context(ref_idx, mbs_x, mb_x, mb_y);
  }

  PlaneState(int width, int height)
      : mbs_x(width / 16),
        mbs_y(height / 16),
        mb_type(static_cast<size_t>(mbs_x) * mbs_y),
        mode4(static_cast<size_t>(mbs_x) * mbs_y * 16),
        cbf4(mode4.size()),
        cbp8(static_cast<size_t>(mbs_x) * mbs_y * 4),
        skip(mb_type.size()),
        mv_x(mb_type.size()),
        mv_y(mb_type.size()),
        td(mb_type.size()),
        td16(mb_type.size()),
        shared(mb_type.size()),
        ref_idx(mb_type.size()),
        lists(mb_type.size()),
        mv_x1(mb_type.size()),
        mv_y1(mb_type.size()),
        transform(mb_type.size()) {}
  // Format 1.6: whether a non-skip macroblock codes a cross-plane scale (the co-located
  // source macroblock has a nonzero residual).
  bool codes_cross_scale(int mb_x, int mb_y) const { return cross && cross->nonzero(mb_x, mb_y); }
  // Whether macroblock i may take over the co-located first-plane vector.
  bool can_share(size_t i) const { return colocated && colocated->inter[i]; }
  // Records the macroblock's motion into a MotionField (P planes).
  void export_motion(MotionField& out) const {
    out.mbs_x = mbs_x;
    out.mbs_y = mbs_y;
    out.inter.resize(mb_type.size());
    for (size_t i = 0; i < mb_type.size(); ++i) out.inter[i] = mb_type[i] == kMbInter;
    out.skip = skip;
    out.mv_x = mv_x;
    out.mv_y = mv_y;
    out.ref_idx = ref_idx;
  }
  // The reference of the co-located first-plane macroblock (shared motion).
  int colocated_ref(size_t i) const {
    return colocated && i < colocated->ref_idx.size() ? colocated->ref_idx[i] : 0;
  }
  // Motion vector predictor of a macroblock that predicts from reference `ref`: the left one's
  // if inter from the same reference, else the top one's if so, else the left one's if inter,
  // else the top one's if inter, else zero (with one reference: the left one's if inter, else
  // the top one's if inter, else zero).
  void mv_predictor(int mb_x, int mb_y, int* px, int* py, int ref = 0) const {
    *px = *py = 0;
    if (partitions) return grid_mv_predictor(mb_x, mb_y, px, py, ref);
    const auto inter = [&](int x, int y) {
      return x >= 0 && y >= 0 && mb_type[static_cast<size_t>(y) * mbs_x + x] == kMbInter;
    };
    const auto same_ref = [&](int x, int y) {
      return inter(x, y) && ref_idx[static_cast<size_t>(y) * mbs_x + x] == ref;
    };
    if (same_ref(mb_x - 1, mb_y)) {
      const size_t i = static_cast<size_t>(mb_y) * mbs_x + mb_x - 1;
      *px = mv_x[i];
      *py = mv_y[i];
    } else if (same_ref(mb_x, mb_y - 1)) {
      const size_t i = static_cast<size_t>(mb_y - 1) * mbs_x + mb_x;
      *px = mv_x[i];
      *py = mv_y[i];
    } else if (inter(mb_x - 1, mb_y)) {
      const size_t i = static_cast<size_t>(mb_y) * mbs_x + mb_x - 1;
      *px = mv_x[i];
      *py = mv_y[i];
    } else if (inter(mb_x, mb_y - 1)) {
      const size_t i = static_cast<size_t>(mb_y - 1) * mbs_x + mb_x;
      *px = mv_x[i];
      *py = mv_y[i];
    }
  }
  // Format 1.7: the same rule on the 8x8 blocks left of and above the macroblock's top-left one
  // (so on the partitions next to it).
  void grid_mv_predictor(int mb_x, int mb_y, int* px, int* py, int ref) const {
    const int x = 2 * mb_x, y = 2 * mb_y;
    const auto ref_at = [&](int gx, int gy) {
      return gx >= 0 && gy >= 0 ? static_cast<int>(grid.ref[grid.index(gx, gy)]) : -1;
    };
    const auto take = [&](int gx, int gy) {
      *px = grid.mv_x[grid.index(gx, gy)];
      *py = grid.mv_y[grid.index(gx, gy)];
    };
    const int left = ref_at(x - 1, y), top = ref_at(x, y - 1);
    if (left == ref)
      take(x - 1, y);
    else if (top == ref)
      take(x, y - 1);
    else if (left >= 0)
      take(x - 1, y);
    else if (top >= 0)
      take(x, y - 1);
  }
  // Format 1.11 (merge, docs/bitstream.md 4.14): the vectors a skip or 16x16 inter macroblock of
  // a P plane may take besides the predictor (px, py) of reference 0: those of the left, top,
  // top-right (when inside the plane), top-left, second-left and second-above macroblocks, in
  // that order, that are inter on reference 0 (a partitioned one: its first partition's), then
  // the co-located macroblock's in reference 0 (reference_motion) if inter on its reference 0;
  // each when it differs from the predictor and from the ones taken before; at most
  // kMergeCandidates. Returns their count.
  int merge_candidates(int mb_x, int mb_y, int px, int py, int cand[][2]) const {
    int n = 0;
    // A vector not seen yet, while there is room.
    const auto add = [&](int mx, int my) {
      if (n == kMergeCandidates || (mx == px && my == py)) return;
      for (int k = 0; k < n; ++k)
        if (cand[k][0] == mx && cand[k][1] == my) return;
      cand[n][0] = mx;
      cand[n][1] = my;
      ++n;
    };
    const auto take = [&](int x, int y) {
      if (x < 0 || y < 0 || x >= mbs_x) return;
      const size_t i = static_cast<size_t>(y) * mbs_x + x;
      if (mb_type[i] == kMbInter && ref_idx[i] == 0) add(mv_x[i], mv_y[i]);
    };
    take(mb_x - 1, mb_y);
    take(mb_x, mb_y - 1);
    if (mb_y > 0 && mb_x + 1 < mbs_x) take(mb_x + 1, mb_y - 1);
    take(mb_x - 1, mb_y - 1);
    take(mb_x - 2, mb_y);
    take(mb_x, mb_y - 2);
    // The co-located macroblock of reference 0, when inter on its own reference 0.
    const size_t c = static_cast<size_t>(mb_y) * mbs_x + mb_x;
    if (reference_motion && reference_motion->inter[c] && reference_motion->ref_idx[c] == 0)
      add(reference_motion->mv_x[c], reference_motion->mv_y[c]);
    return n;
  }
  // Format 1.11: takes `m` (the plane's motion in reference 0) as merge's co-located record when
  // merge is on and it covers this plane's macroblock grid; otherwise there is none. The encoder
  // and the decoder decide alike.
  void use_reference_motion(const MotionField* m) {
    const size_t count = skip.size();
    const bool fits = m && m->mbs_x == mbs_x && m->mbs_y == mbs_y && m->inter.size() == count &&
                      m->ref_idx.size() == count && m->mv_x.size() == count &&
                      m->mv_y.size() == count;
    reference_motion = merge && fits ? m : nullptr;
  }
  // B planes: the predictor of the list's vector, the left macroblock's if it uses the list,
  // else the top one's if it does, else zero.
  void mv_predictor_list(int list, int mb_x, int mb_y, int* px, int* py) const {
    *px = *py = 0;
    const auto uses = [&](int x, int y) {
      return x >= 0 && y >= 0 && (lists[static_cast<size_t>(y) * mbs_x + x] >> list) & 1;
    };
    size_t i;
    if (uses(mb_x - 1, mb_y))
      i = static_cast<size_t>(mb_y) * mbs_x + mb_x - 1;
    else if (uses(mb_x, mb_y - 1))
      i = static_cast<size_t>(mb_y - 1) * mbs_x + mb_x;
    else
      return;
    *px = list ? mv_x1[i] : mv_x[i];
    *py = list ? mv_y1[i] : mv_y[i];
  }
  // Context increment of a flag: how many of the left and top macroblocks of (mb_x, mb_y) have
  // pred(v[their index]) (0 outside the plane); v is a per-macroblock array.
  template <class Pred>
  int neighbour_count(const std::vector<uint8_t>& v, int mb_x, int mb_y, Pred pred) const {
    const size_t i = static_cast<size_t>(mb_y) * mbs_x + mb_x;
    return (mb_x > 0 && pred(v[i - 1]) ? 1 : 0) + (mb_y > 0 && pred(v[i - mbs_x]) ? 1 : 0);
  }
  int w4() const { return mbs_x * 4; }
  int w8() const { return mbs_x * 2; }
  int8_t& mode_at(int gx, int gy) { return mode4[static_cast<size_t>(gy) * w4() + gx]; }
  uint8_t& cbf_at(int gx, int gy) { return cbf4[static_cast<size_t>(gy) * w4() + gx]; }
  uint8_t& cbp_at(int gx, int gy) { return cbp8[static_cast<size_t>(gy) * w8() + gx]; }
};

// Prediction of an inter macroblock of a B plane (format 1.5): list 0, list 1, their rounded
// average (bi) or direct (bi with both lists' predicted vectors, no vector difference coded).
enum BPred : uint8_t { kBL0 = 0, kBL1 = 1, kBBi = 2, kBDirect = 3 };
inline int b_pred_lists(BPred p) { return p == kBL0 ? 1 : (p == kBL1 ? 2 : 3); }

// One macroblock's decisions: type, modes and quantized levels (raster order within each block).
struct MacroblockData {
  MbType type = kMbI16x16;
  int i16_mode = kIntraDc;
  int8_t modes[16] = {};        // I4x4: per block in z-order; I8x8: modes[0..3] per 8x8 block
  uint8_t cbp = 0;              // bit q: 8x8 quadrant q has a nonzero level
  int32_t levels[16][16] = {};  // 4x4 blocks in z-order (I4x4, I16x16)
  int32_t levels8[4][64] = {};  // 8x8 blocks (I8x8, and 8x8 transforms of format 1.6)
  // Format 1.6 (larger transforms), inter and I16x16: the residual's transform (4, 8 or 16;
  // 16: cbp is 0 or 15, one block) and the 16x16 block's levels.
  int transform = 4;
  int32_t levels16[256] = {};
  bool skip = false;  // inter: motion = predictor, no residual
  // Format 1.11 (merge), P planes: a skip's vector, 0 = the predictor, k = merge candidate k - 1
  // (PlaneState::merge_candidates); of another 16x16 inter macroblock, 0 = coded with ref_idx
  // and a vector difference, k = merge candidate k - 1 on reference 0.
  int merge_idx = 0;
  bool td = false;  // inter: temporal-difference prediction with modes[0..15]
  // Format 1.12, with td: the difference is predicted by the 16x16 mode i16_mode (TD16).
  bool td16 = false;
  bool shared = false;     // inter: the co-located first-plane vector (format 1.4)
  int mv_x = 0, mv_y = 0;  // inter: motion vector (samples, or quarter samples)
  int ref_idx = 0;         // inter, P planes: index into the reference list (format 1.6)
  // Format 1.7, P planes: the partition type (PartitionType) of a plain inter macroblock and,
  // when not 16x16, each partition's reference and vector (mv_x, mv_y, ref_idx: partition 0's).
  int partition = kPart16x16;
  int part_ref[4] = {}, part_mv_x[4] = {}, part_mv_y[4] = {};
  // B planes: the prediction of an inter macroblock and its list 1 vector (mv_x, mv_y being
  // the list 0 one). Skip is a direct macroblock without residual.
  BPred b_pred = kBDirect;
  int mv_x1 = 0, mv_y1 = 0;
  // Format 1.6, Y and Z planes: cross-plane scale alpha (kCrossScales; 0 when not coded).
  int cross_scale = 0;
};

inline int mode_count4(const PlaneCodingParams& p) {
  return p.geometry_modes ? kIntra4x4ModeCount : 9;
}

// Most probable mode of the block whose top-left 4x4 unit is (gx, gy).
inline int most_probable_mode(PlaneState& st, int gx, int gy, bool for_8x8) {
  if (gx == 0 || gy == 0) return kIntraDc;
  int m = std::min(st.mode_at(gx - 1, gy), st.mode_at(gx, gy - 1));
  if (for_8x8 && m >= 9) m = kIntraDc;
  return m;
}

inline bool any_nonzero(const int32_t* v, int n) {
  int i = 0;
  for (; i + 16 <= n; i += 16) {  // sixteen at a time (the loop vectorizes), then the verdict
    int32_t any = 0;
    for (int k = 0; k < 16; ++k) any |= v[i + k];
    if (any) return true;
  }
  for (; i < n; ++i)
    if (v[i]) return true;
  return false;
}

template <class Coder>
void write_mode(Coder& coder, ContextSet& ctx, int mode, int mpm, int mode_count) {
  set_group(coder, kSyntaxModes);
  if (mode == mpm) {
    coder.encode(ctx.prev_mode_flag[0], 1);
    return;
  }
  coder.encode(ctx.prev_mode_flag[0], 0);
  const int rem = mode < mpm ? mode : mode - 1;
  const int bits = mode_count > 9 ? 4 : 3;
  for (int b = 0; b < bits; ++b) coder.encode(ctx.rem_mode[0], (rem >> b) & 1);
}

template <class Coder>
void write_exp_golomb0(Coder& coder, uint32_t value, int k = 0) {
  while (value >= (1u << k)) {
    coder.encode_bypass(1);
    value -= 1u << k;
    ++k;
  }
  coder.encode_bypass(0);
  while (k--) coder.encode_bypass((value >> k) & 1);
}

// Raster index of scan position i of an n x n block (n = 4, 8, 16); residual category and
// significance-map context of scan position i.
inline int scan_position(int n, int i) {
  return n == 4 ? kZigzag4x4[i] : (n == 8 ? kZigzag8x8[i] : kZigzag16x16[i]);
}
inline int residual_category(int n) { return n == 4 ? 0 : (n == 8 ? 1 : 2); }
// 16x16: the anti-diagonal x + y of the position, capped at 15 (on the ICT face 2.1 % fewer bits
// than i >> 4 at QP 0 in the slow preset, 0.3 % in the fast one; docs/benchmarks.md).
inline int sig_context(int n, int i) {
  if (n == 16) {
    const int r = kZigzag16x16[static_cast<size_t>(i)];
    return std::min(15, r % 16 + r / 16);
  }
  return n == 4 ? i : (n == 8 ? i >> 2 : i >> 4);
}

// A block size's scan as tables, built once: the raster position and the significance context
// (sig_context) of each scan index.
struct ResidualScan {
  uint16_t position[256];
  uint8_t context[256];
};
template <int N>
const ResidualScan& residual_scan() {
  static_assert(N == 4 || N == 8 || N == 16);
  static const ResidualScan scan = [] {
    ResidualScan s{};
    for (int i = 0; i < N * N; ++i) {
      s.position[i] = static_cast<uint16_t>(scan_position(N, i));
      s.context[i] = static_cast<uint8_t>(sig_context(N, i));
    }
    return s;
  }();
  return scan;
}

// Residual block of N*N levels in raster order (at least one nonzero).
template <int N, class Coder>
void write_residual_n(Coder& coder, ContextSet& ctx, const int32_t* levels) {
  constexpr int count = N * N, cat = N == 4 ? 0 : (N == 8 ? 1 : 2);
  const ResidualScan& scan = residual_scan<N>();
  int last = count - 1;
  while (last > 0 && !levels[scan.position[last]]) --last;
  CabacContext* const sig = ctx.sig[cat];
  CabacContext* const last_ctx = ctx.last[cat];
  set_group(coder, kSyntaxSigMap);
  for (int i = 0; i < count - 1; ++i) {
    const int c = scan.context[i];
    const int significant = levels[scan.position[i]] != 0;
    coder.encode(sig[c], significant);
    if (significant) {
      coder.encode(last_ctx[c], i == last);
      if (i == last) break;
    }
  }
  set_group(coder, kSyntaxLevels);
  CabacContext* const level = ctx.level[cat];
  int num_gt1 = 0, num_eq1 = 0;
  for (int i = last; i >= 0; --i) {
    const int32_t v = levels[scan.position[i]];
    if (!v) continue;
    const uint32_t abs_minus1 = static_cast<uint32_t>(std::abs(v)) - 1;
    coder.encode(level[num_gt1 ? 0 : std::min(4, 1 + num_eq1)], abs_minus1 > 0);
    if (ctx.adaptive_levels) {
      if (abs_minus1 > 0)
        write_exp_golomb0(coder, abs_minus1 - 1, adaptive_order(ctx.level_mean16[cat]));
      update_level_mean(ctx.level_mean16[cat], abs_minus1);
    } else if (abs_minus1 > 0) {
      CabacContext& c = level[5 + std::min(4, num_gt1)];
      uint32_t k = 1;
      for (; k < static_cast<uint32_t>(kLevelPrefixMax) && k < abs_minus1 + 1; ++k)
        coder.encode(c, k < abs_minus1);
      if (abs_minus1 >= static_cast<uint32_t>(kLevelPrefixMax))
        write_exp_golomb0(coder, abs_minus1 - kLevelPrefixMax);
    }
    coder.encode_bypass(v < 0);
    if (abs_minus1 == 0)
      ++num_eq1;
    else
      ++num_gt1;
  }
}

// Residual block of n*n levels (n = 4, 8 or 16) in raster order (at least one nonzero). A bit
// counter is worked on as a local copy: the context updates (byte stores) could otherwise alias
// its sum and keep it in memory.
template <class Coder>
void write_residual(Coder& coder, ContextSet& ctx, const int32_t* levels, int n) {
  const auto write = [&](auto& c) {
    if (n == 4)
      write_residual_n<4>(c, ctx, levels);
    else if (n == 8)
      write_residual_n<8>(c, ctx, levels);
    else
      write_residual_n<16>(c, ctx, levels);
  };
  if constexpr (std::is_trivially_copyable_v<Coder> && sizeof(Coder) <= 16) {
    Coder local = coder;
    write(local);
    coder = local;
  } else {
    write(coder);
  }
}

// ---- Larger transforms (format 1.6, docs/bitstream.md 4.8) ----
// Whether macroblock `mb` codes transform_size: plain inter (not TD, but TD16) and I16x16
// macroblocks of a plane with max_transform > 4, when their cbp is nonzero.
inline bool has_transform_size(const MacroblockData& mb, const PlaneCodingParams& p) {
  return p.max_transform > 4 && mb.cbp != 0 &&
         ((mb.type == kMbInter && (!mb.td || mb.td16)) || mb.type == kMbI16x16);
}
inline int transform_code(int size) { return size == 16 ? 2 : (size == 8 ? 1 : 0); }

// Format 1.13: whether the I16x16 macroblock (mb_x, mb_y) of a plane coded with `p` may take the
// quadratic mode (it reads two rows above and two columns left of the macroblock).
inline bool has_quadratic_mode(const PlaneCodingParams& p, int mb_x, int mb_y) {
  return p.quadratic_intra && mb_x > 0 && mb_y > 0;
}

// transform_size after the cbp: bin 0 (size > 4, context: left and top macroblocks with
// transform code >= 1), then with max_transform 16 and cbp 15 bin 1 (16x16, context: the
// neighbours with code 2). Records the code for later contexts.
template <class Coder>
void write_transform_size(Coder& coder, ContextSet& ctx, const PlaneState& st, int mb_x, int mb_y,
                          int size, int cbp, int max_transform) {
  const size_t i = static_cast<size_t>(mb_y) * st.mbs_x + mb_x;
  const auto count = [&](int code) {
    return (mb_x > 0 && st.transform[i - 1] >= code ? 1 : 0) +
           (mb_y > 0 && st.transform[i - st.mbs_x] >= code ? 1 : 0);
  };
  coder.encode(ctx.transform_size[0][count(1)], size > 4);
  if (size > 4 && max_transform == 16 && cbp == 15)
    coder.encode(ctx.transform_size[1][count(2)], size == 16);
}
// ---- end of larger transforms ----

// Coded block pattern, then the residual blocks (8x8 for I8x8, else 4x4 with coded_block_flag;
// format 1.6: transform_size, then 8x8 blocks per cbp quadrant or one 16x16 block).
template <class Coder>
void write_cbp_and_4x4_residuals(Coder& coder, ContextSet& ctx, PlaneState& st, int mb_x, int mb_y,
                                 const MacroblockData& mb, const PlaneCodingParams& params) {
  const int gx0 = mb_x * 4, gy0 = mb_y * 4;
  const int cx0 = mb_x * 2, cy0 = mb_y * 2;
  if (st.codes_cross_scale(mb_x, mb_y)) {  // format 1.6
    set_group(coder, kSyntaxMbType);
    write_cross_scale(coder, ctx.cross_scale, ctx.cross_sign[0], mb.cross_scale);
  }
  set_group(coder, kSyntaxCbp);
  for (int q = 0; q < 4; ++q) {
    const int cx = cx0 + (q & 1), cy = cy0 + (q >> 1);
    const int left = cx > 0 ? st.cbp_at(cx - 1, cy) : 0;
    const int top = cy > 0 ? st.cbp_at(cx, cy - 1) : 0;
    const int bit = (mb.cbp >> q) & 1;
    coder.encode(ctx.cbp[left + 2 * top], bit);
    st.cbp_at(cx, cy) = static_cast<uint8_t>(bit);
  }
  const size_t mb_index = static_cast<size_t>(mb_y) * st.mbs_x + mb_x;
  int size = mb.type == kMbI8x8 ? 8 : 4;
  if (has_transform_size(mb, params)) {
    size = mb.transform;
    set_group(coder, kSyntaxMbType);
    write_transform_size(coder, ctx, st, mb_x, mb_y, size, mb.cbp, params.max_transform);
  }
  st.transform[mb_index] = static_cast<uint8_t>(transform_code(size));
  if (size == 16) {
    for (int i = 0; i < 16; ++i) st.cbf_at(gx0 + i % 4, gy0 + i / 4) = 1;
    write_residual(coder, ctx, mb.levels16, 16);
    return;
  }
  if (size == 8) {
    for (int q = 0; q < 4; ++q) {
      const int bit = (mb.cbp >> q) & 1;
      for (int i = 0; i < 4; ++i)
        st.cbf_at(gx0 + (q & 1) * 2 + (i & 1), gy0 + (q >> 1) * 2 + (i >> 1)) =
            static_cast<uint8_t>(bit);
      if (bit) write_residual(coder, ctx, mb.levels8[q], 8);
    }
    return;
  }
  for (int b = 0; b < 16; ++b) {
    const int gx = gx0 + block_x(b), gy = gy0 + block_y(b);
    if (!((mb.cbp >> (b >> 2)) & 1)) {
      st.cbf_at(gx, gy) = 0;
      continue;
    }
    const int left = gx > 0 ? st.cbf_at(gx - 1, gy) : 0;
    const int top = gy > 0 ? st.cbf_at(gx, gy - 1) : 0;
    const int coded = any_nonzero(mb.levels[b], 16) ? 1 : 0;
    set_group(coder, kSyntaxCbp);
    coder.encode(ctx.cbf[left + 2 * top], coded);
    st.cbf_at(gx, gy) = static_cast<uint8_t>(coded);
    if (coded) write_residual(coder, ctx, mb.levels[b], 4);
  }
}

template <class Coder>
void write_mvd(Coder& coder, ContextSet& ctx, int component, int value) {
  set_group(coder, kSyntaxMotion);
  coder.encode(ctx.mvd_zero[component], value != 0);
  if (!value) return;
  coder.encode_bypass(value < 0);
  write_exp_golomb0(coder, static_cast<uint32_t>(std::abs(value) - 1));
}

// The intra part of a macroblock (type, modes, residuals), after the inter syntax of P and B
// planes.
template <class Coder>
void write_intra_macroblock(Coder& coder, ContextSet& ctx, PlaneState& st, int mb_x, int mb_y,
                            const MacroblockData& mb, const PlaneCodingParams& params) {
  const auto neighbour_type = [&](int dx, int dy, MbType t) {
    const int x = mb_x + dx, y = mb_y + dy;
    if (x < 0 || y < 0) return 0;
    return st.mb_type[static_cast<size_t>(y) * st.mbs_x + x] == t ? 1 : 0;
  };
  set_group(coder, kSyntaxMbType);
  const int mb_index = mb_y * st.mbs_x + mb_x;
  const int is_i16 = mb.type == kMbI16x16;
  coder.encode(ctx.is_i16[neighbour_type(-1, 0, kMbI16x16) + neighbour_type(0, -1, kMbI16x16)],
               is_i16);
  if (!is_i16)
    coder.encode(ctx.is_8x8[neighbour_type(-1, 0, kMbI8x8) + neighbour_type(0, -1, kMbI8x8)],
                 mb.type == kMbI8x8);
  st.mb_type[mb_index] = mb.type;
  const int gx0 = mb_x * 4, gy0 = mb_y * 4;
  if (mb.type == kMbI16x16) {
    set_group(coder, kSyntaxModes);
    const bool quadratic = mb.i16_mode == kIntra16x16Quadratic;
    GVKIT_CHECK(!quadratic || has_quadratic_mode(params, mb_x, mb_y), "quadratic mode unavailable");
    if (has_quadratic_mode(params, mb_x, mb_y))  // format 1.13
      coder.encode(ctx.i16_quadratic[0], quadratic);
    if (!quadratic) {
      coder.encode(ctx.i16_mode[0], mb.i16_mode & 1);
      coder.encode(ctx.i16_mode[1], (mb.i16_mode >> 1) & 1);
    }
    for (int i = 0; i < 16; ++i) st.mode_at(gx0 + i % 4, gy0 + i / 4) = kIntraDc;
  } else if (mb.type == kMbI8x8) {
    for (int q = 0; q < 4; ++q) {
      const int gx = gx0 + (q & 1) * 2, gy = gy0 + (q >> 1) * 2;
      write_mode(coder, ctx, mb.modes[q], most_probable_mode(st, gx, gy, true), 9);
      for (int i = 0; i < 4; ++i) st.mode_at(gx + (i & 1), gy + (i >> 1)) = mb.modes[q];
    }
  } else {
    for (int b = 0; b < 16; ++b) {
      const int gx = gx0 + block_x(b), gy = gy0 + block_y(b);
      write_mode(coder, ctx, mb.modes[b], most_probable_mode(st, gx, gy, false),
                 mode_count4(params));
      st.mode_at(gx, gy) = mb.modes[b];
    }
  }
  write_cbp_and_4x4_residuals(coder, ctx, st, mb_x, mb_y, mb, params);
}

// Format 1.11: merge_idx (0..n) as truncated unary, bin k in contexts[k]; nothing when n = 0.
template <class Coder>
void write_merge_idx(Coder& coder, CabacContext* contexts, int idx, int n) {
  for (int k = 0; k < n; ++k) {
    coder.encode(contexts[k], idx > k);
    if (idx <= k) return;
  }
}

// Writes one macroblock of a B plane (format 1.5): skip (direct, no residual), else is_inter;
// an inter macroblock then codes direct / bi / L0 / L1, the vector differences of the lists it
// uses (not for direct) and its residual.
template <class Coder>
void write_b_macroblock(Coder& coder, ContextSet& ctx, PlaneState& st, int mb_x, int mb_y,
                        const MacroblockData& mb, const PlaneCodingParams& params) {
  const int mb_index = mb_y * st.mbs_x + mb_x;
  const auto flag_ctx = [&](const std::vector<uint8_t>& v, auto pred) {
    return st.neighbour_count(v, mb_x, mb_y, pred);
  };
  set_group(coder, kSyntaxMbType);
  const bool inter = mb.type == kMbInter;
  const bool skip = inter && mb.skip;
  coder.encode(ctx.skip[flag_ctx(st.skip, [](uint8_t k) { return k != 0; })], skip);
  st.skip[mb_index] = skip;
  st.td[mb_index] = 0;
  st.td16[mb_index] = 0;
  if (!skip)
    coder.encode(ctx.is_inter[flag_ctx(st.mb_type, [](uint8_t t) { return t == kMbInter; })],
                 inter);
  if (!inter) {
    st.lists[mb_index] = 0;
    write_intra_macroblock(coder, ctx, st, mb_x, mb_y, mb, params);
    return;
  }
  st.mb_type[mb_index] = kMbInter;
  const BPred pred = skip ? kBDirect : mb.b_pred;
  int p0x, p0y, p1x, p1y;
  st.mv_predictor_list(0, mb_x, mb_y, &p0x, &p0y);
  st.mv_predictor_list(1, mb_x, mb_y, &p1x, &p1y);
  if (!skip) {
    coder.encode(ctx.b_pred[0], pred == kBDirect);
    if (pred != kBDirect) {
      coder.encode(ctx.b_pred[1], pred == kBBi);
      if (pred != kBBi) coder.encode(ctx.b_pred[2], pred == kBL1);
    }
  }
  const int lists = b_pred_lists(pred);
  const bool direct = pred == kBDirect;
  if (!direct && (lists & 1)) {
    write_mvd(coder, ctx, 0, mb.mv_x - p0x);
    write_mvd(coder, ctx, 1, mb.mv_y - p0y);
  }
  if (!direct && (lists & 2)) {
    write_mvd(coder, ctx, 0, mb.mv_x1 - p1x);
    write_mvd(coder, ctx, 1, mb.mv_y1 - p1y);
  }
  st.lists[mb_index] = static_cast<uint8_t>(lists);
  st.mv_x[mb_index] = static_cast<int16_t>(direct ? p0x : (lists & 1 ? mb.mv_x : 0));
  st.mv_y[mb_index] = static_cast<int16_t>(direct ? p0y : (lists & 1 ? mb.mv_y : 0));
  st.mv_x1[mb_index] = static_cast<int16_t>(direct ? p1x : (lists & 2 ? mb.mv_x1 : 0));
  st.mv_y1[mb_index] = static_cast<int16_t>(direct ? p1y : (lists & 2 ? mb.mv_y1 : 0));
  const int gx0 = mb_x * 4, gy0 = mb_y * 4;
  for (int i = 0; i < 16; ++i) st.mode_at(gx0 + i % 4, gy0 + i / 4) = kIntraDc;
  if (skip) {
    for (int i = 0; i < 16; ++i) st.cbf_at(gx0 + i % 4, gy0 + i / 4) = 0;
    for (int q = 0; q < 4; ++q) st.cbp_at(mb_x * 2 + (q & 1), mb_y * 2 + (q >> 1)) = 0;
    return;
  }
  write_cbp_and_4x4_residuals(coder, ctx, st, mb_x, mb_y, mb, params);
}

// ---- Format 1.7, inter partitions (docs/bitstream.md 4.11) ----
// The motion of a macroblock of partition type mb.partition (not 16x16): every partition's
// ref_idx (several references), then every partition's vector difference against its
// predictor (partition_mv_predictor). Records the motion (the macroblock's vector: partition
// 0's) and the state of a plain inter macroblock without TD.
template <class Coder>
void write_partitioned_motion(Coder& coder, ContextSet& ctx, PlaneState& st, int mb_x, int mb_y,
                              const MacroblockData& mb, const PlaneCodingParams& params) {
  const int t = mb.partition, count = partition_count(t);
  const size_t mb_index = static_cast<size_t>(mb_y) * st.mbs_x + mb_x;
  set_group(coder, kSyntaxMotion);
  for (int k = 0; k < count && params.ref_count > 1; ++k) {
    const PartitionRect r = partition_rect(t, k);
    write_ref_idx(coder, ctx.ref_idx, st.grid.ref_context(2 * mb_x + r.x, 2 * mb_y + r.y),
                  mb.part_ref[k], params.ref_count);
    // The predictors of later partitions see this reference (vectors follow below).
    st.grid.set(mb_x, mb_y, r, mb.part_ref[k], 0, 0);
  }
  for (int k = 0; k < count; ++k) st.grid.set(mb_x, mb_y, partition_rect(t, k), -1, 0, 0);
  for (int k = 0; k < count; ++k) {
    int px, py;
    partition_mv_predictor(st.grid, mb_x, mb_y, t, k, mb.part_ref[k], &px, &py);
    write_mvd(coder, ctx, 0, mb.part_mv_x[k] - px);
    write_mvd(coder, ctx, 1, mb.part_mv_y[k] - py);
    st.grid.set(mb_x, mb_y, partition_rect(t, k), mb.part_ref[k], mb.part_mv_x[k], mb.part_mv_y[k]);
  }
  st.ref_idx[mb_index] = static_cast<uint8_t>(mb.part_ref[0]);
  st.mv_x[mb_index] = static_cast<int16_t>(mb.part_mv_x[0]);
  st.mv_y[mb_index] = static_cast<int16_t>(mb.part_mv_y[0]);
  st.td[mb_index] = 0;
  st.td16[mb_index] = 0;
  const int gx0 = mb_x * 4, gy0 = mb_y * 4;
  for (int i = 0; i < 16; ++i) st.mode_at(gx0 + i % 4, gy0 + i / 4) = kIntraDc;
}
// ---- end of inter partitions ----

// Writes one macroblock at (mb_x, mb_y) and records its state for later contexts.
template <class Coder>
void write_macroblock(Coder& coder, ContextSet& ctx, PlaneState& st, int mb_x, int mb_y,
                      const MacroblockData& mb, const PlaneCodingParams& params) {
  if (st.bidirectional) {
    write_b_macroblock(coder, ctx, st, mb_x, mb_y, mb, params);
    return;
  }
  const int mb_index = mb_y * st.mbs_x + mb_x;
  const auto flag_ctx = [&](const std::vector<uint8_t>& v, auto pred) {
    return st.neighbour_count(v, mb_x, mb_y, pred);
  };
  set_group(coder, kSyntaxMbType);
  if (st.predicted) {
    const bool shared = st.can_share(mb_index) && mb.type == kMbInter && mb.shared;
    if (st.can_share(mb_index))
      coder.encode(ctx.shared_mv[flag_ctx(st.shared, [](uint8_t k) { return k != 0; })], shared);
    st.shared[mb_index] = shared;
    const int inter = mb.type == kMbInter;
    if (!shared)
      coder.encode(ctx.is_inter[flag_ctx(st.mb_type, [](uint8_t t) { return t == kMbInter; })],
                   inter);
    if (inter) {
      st.mb_type[mb_index] = kMbInter;
      if (shared)
        coder.encode(ctx.shared_skip[st.colocated->skip[mb_index]], mb.skip);
      else
        coder.encode(ctx.skip[flag_ctx(st.skip, [](uint8_t k) { return k != 0; })], mb.skip);
      st.skip[mb_index] = mb.skip;
      // ---- Format 1.7, inter partitions (docs/bitstream.md 4.11) ----
      if (st.partitions && !mb.skip && !shared) {
        set_group(coder, kSyntaxMotion);
        write_partition_type(coder, ctx.partition, mb.partition);
        if (mb.partition != kPart16x16) {
          write_partitioned_motion(coder, ctx, st, mb_x, mb_y, mb, params);
          write_cbp_and_4x4_residuals(coder, ctx, st, mb_x, mb_y, mb, params);
          return;
        }
      }
      // ---- end of inter partitions ----
      // Format 1.11, merge: a skip's vector, or whether (and which) a 16x16 inter macroblock
      // takes a candidate's vector on reference 0 instead of coding ref_idx and a difference.
      int cand[kMergeCandidates][2];
      int candidates = 0;
      if (st.merge && !shared) {
        int p0x, p0y;
        st.mv_predictor(mb_x, mb_y, &p0x, &p0y, 0);
        candidates = st.merge_candidates(mb_x, mb_y, p0x, p0y, cand);
        GVKIT_CHECK(mb.merge_idx >= 0 && mb.merge_idx <= candidates,
                    "merge index without its candidate");
        set_group(coder, kSyntaxMotion);
        write_merge_idx(coder, mb.skip ? ctx.merge_idx : ctx.merge_inter, mb.merge_idx, candidates);
      }
      const bool merged = !mb.skip && !shared && mb.merge_idx > 0;
      // Format 1.6: the reference (skip: 0; shared: the co-located macroblock's).
      const int ref = shared ? st.colocated_ref(mb_index) : (mb.skip || merged ? 0 : mb.ref_idx);
      if (!mb.skip && !shared && !merged && params.ref_count > 1) {
        set_group(coder, kSyntaxMotion);
        write_ref_idx(coder, ctx.ref_idx, st.ref_context(mb_x, mb_y), ref, params.ref_count);
      }
      st.ref_idx[mb_index] = static_cast<uint8_t>(ref);
      int px, py;
      if (shared) {
        px = st.colocated->mv_x[mb_index];
        py = st.colocated->mv_y[mb_index];
      } else {
        st.mv_predictor(mb_x, mb_y, &px, &py, ref);
      }
      if (!shared && mb.merge_idx > 0) {
        px = cand[mb.merge_idx - 1][0];
        py = cand[mb.merge_idx - 1][1];
        GVKIT_CHECK(mb.skip || (mb.mv_x == px && mb.mv_y == py), "merged vector differs");
      }
      if (!mb.skip && !shared && !merged) {
        write_mvd(coder, ctx, 0, mb.mv_x - px);
        write_mvd(coder, ctx, 1, mb.mv_y - py);
      }
      st.mv_x[mb_index] = static_cast<int16_t>(mb.skip || shared ? px : mb.mv_x);
      st.mv_y[mb_index] = static_cast<int16_t>(mb.skip || shared ? py : mb.mv_y);
      if (st.partitions)
        st.grid.set_macroblock(mb_x, mb_y, ref, st.mv_x[mb_index], st.mv_y[mb_index]);
      const int gx0 = mb_x * 4, gy0 = mb_y * 4;
      const bool td = !mb.skip && params.td_prediction && mb.td;
      set_group(coder, kSyntaxMbType);
      if (!mb.skip && params.td_prediction)
        coder.encode(ctx.td_flag[flag_ctx(st.td, [](uint8_t k) { return k != 0; })], td);
      st.td[mb_index] = td;
      const bool td16 = td && params.td16 && mb.td16;
      if (td && params.td16) {  // format 1.12
        coder.encode(ctx.td16[flag_ctx(st.td16, [](uint8_t k) { return k != 0; })], td16);
        if (td16) {
          set_group(coder, kSyntaxModes);
          const bool quadratic = mb.i16_mode == kIntra16x16Quadratic;
          GVKIT_CHECK(!quadratic || has_quadratic_mode(params, mb_x, mb_y),
                      "quadratic mode unavailable");
          if (has_quadratic_mode(params, mb_x, mb_y))  // format 1.13
            coder.encode(ctx.td16_quadratic[0], quadratic);
          if (!quadratic) {
            coder.encode(ctx.td16_mode[0], mb.i16_mode & 1);
            coder.encode(ctx.td16_mode[1], (mb.i16_mode >> 1) & 1);
          }
        }
      }
      st.td16[mb_index] = td16;
      if (td && !td16) {
        for (int b = 0; b < 16; ++b) {
          const int gx = gx0 + block_x(b), gy = gy0 + block_y(b);
          write_mode(coder, ctx, mb.modes[b], most_probable_mode(st, gx, gy, false),
                     mode_count4(params));
          st.mode_at(gx, gy) = mb.modes[b];
        }
      } else {
        for (int i = 0; i < 16; ++i) st.mode_at(gx0 + i % 4, gy0 + i / 4) = kIntraDc;
      }
      if (mb.skip) {
        for (int i = 0; i < 16; ++i) st.cbf_at(gx0 + i % 4, gy0 + i / 4) = 0;
        for (int q = 0; q < 4; ++q) st.cbp_at(mb_x * 2 + (q & 1), mb_y * 2 + (q >> 1)) = 0;
        return;
      }
      write_cbp_and_4x4_residuals(coder, ctx, st, mb_x, mb_y, mb, params);
      return;
    }
    st.skip[mb_index] = 0;
    st.td[mb_index] = 0;
    st.td16[mb_index] = 0;
    st.ref_idx[mb_index] = 0;
    if (st.partitions) st.grid.set_macroblock(mb_x, mb_y, -1, 0, 0);  // format 1.7
  }
  write_intra_macroblock(coder, ctx, st, mb_x, mb_y, mb, params);
}

// Whether the sample at (px, py) is reconstructed before the block whose z-order index (in 4x4
// units) is `block` of macroblock (mb_x, mb_y); width is the plane width.
inline bool is_coded(int px, int py, int width, int mb_x, int mb_y, int block) {
  if (px < 0 || py < 0 || px >= width) return false;
  const int mx = px / 16, my = py / 16;
  if (my != mb_y) return my < mb_y;
  if (mx != mb_x) return mx < mb_x;
  return zorder_index((px % 16) / 4, (py % 16) / 4) < block;
}

// Prediction + residual -> reconstructed samples of an n x n block at (x0, y0); pred's rows are
// pred_stride apart.
inline void reconstruct_block(int n, const int32_t* pred, const int32_t* levels,
                              const PlaneCodingParams& p, uint16_t* plane, int stride, int x0,
                              int y0, int pred_stride = 0) {
  const int count = n * n;
  const int max_value = (1 << p.bit_depth) - 1;
  if (pred_stride == 0) pred_stride = n;
  uint16_t* dst = plane + static_cast<size_t>(y0) * stride + x0;
  // No residual: the clipped prediction.
  if (!any_nonzero(levels, count))
    return store_reconstruction(n, pred, pred_stride, nullptr, max_value, dst, stride);
  if (p.lossless) {
    // Near-lossless: a level counts 2 near + 1 samples (|level| < 2^24, so no overflow).
    const int64_t step = 2 * static_cast<int64_t>(p.near_lossless) + 1;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const int64_t v = pred[y * pred_stride + x] + levels[y * n + x] * step;
        dst[static_cast<size_t>(y) * stride + x] =
            static_cast<uint16_t>(v < 0 ? 0 : (v > max_value ? max_value : v));
      }
    return;
  }
  int32_t residual[256];
  inverse_residual(n, levels, p.qp_prime, residual);
  store_reconstruction(n, pred, pred_stride, residual, max_value, dst, stride);
}

// The residual of an inter or I16x16 macroblock added to its 16x16 prediction pred16 at
// (x0, y0): sixteen 4x4 blocks, four 8x8 blocks or one 16x16 block by mb.transform.
inline void reconstruct_macroblock_residual(const int32_t* pred16, const MacroblockData& mb,
                                            const PlaneCodingParams& p, uint16_t* plane, int stride,
                                            int x0, int y0) {
  if (mb.transform == 16) {
    reconstruct_block(16, pred16, mb.levels16, p, plane, stride, x0, y0);
    return;
  }
  const int n = mb.transform == 8 ? 8 : 4;
  const bool levels =
      n == 8 ? any_nonzero(&mb.levels8[0][0], 256) : any_nonzero(&mb.levels[0][0], 256);
  if (!levels)  // the clipped prediction, in one store
    return store_reconstruction(16, pred16, 16, nullptr, (1 << p.bit_depth) - 1,
                                plane + static_cast<size_t>(y0) * stride + x0, stride);
  for (int b = 0; b < (n == 8 ? 4 : 16); ++b) {
    const int bx = n == 8 ? (b & 1) * 8 : block_x(b) * 4,
              by = n == 8 ? (b >> 1) * 8 : block_y(b) * 4;
    reconstruct_block(n, pred16 + by * 16 + bx, n == 8 ? mb.levels8[b] : mb.levels[b], p, plane,
                      stride, x0 + bx, y0 + by, 16);
  }
}

// Inter prediction of the 16x16 macroblock at (x0, y0): the reference block displaced by the
// motion vector (quarter samples when quarter_pel), the reference extended at its edges.
inline void predict_inter(const SamplePlane& ref, int x0, int y0, int mv_x, int mv_y,
                          bool quarter_pel, int bit_depth, int32_t* pred) {
  predict_motion_block(ref, x0, y0, 16, 16, mv_x, mv_y, quarter_pel, bit_depth, pred);
}

// Format 1.7: the inter prediction of a partitioned P macroblock at (x0, y0) (16x16, row-major
// into pred): each partition's block from its own reference reference(ref_idx) at its vector.
template <class ReferenceOf>
void predict_partitions(const MacroblockData& mb, int x0, int y0, bool quarter_pel, int bit_depth,
                        const ReferenceOf& reference, int32_t* pred) {
  for (int k = 0; k < partition_count(mb.partition); ++k) {
    const PartitionRect r = partition_rect(mb.partition, k);
    int32_t block[256];
    const int w = 8 * r.w, h = 8 * r.h;
    predict_motion_block(reference(mb.part_ref[k]), x0 + 8 * r.x, y0 + 8 * r.y, w, h,
                         mb.part_mv_x[k], mb.part_mv_y[k], quarter_pel, bit_depth, block);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) pred[(8 * r.y + y) * 16 + 8 * r.x + x] = block[y * w + x];
  }
}

// Inter prediction of a B macroblock at (x0, y0) from list 0 (ref0) and list 1 (ref1): one
// list's motion-compensated block, or for bi and direct the average (p0 + p1 + 1) >> 1 of both
// (H.264's default weighted prediction). Direct uses the vectors given (the predictors).
inline void predict_b_inter(const SamplePlane& ref0, const SamplePlane& ref1, int x0, int y0,
                            BPred pred_kind, int mv_x0, int mv_y0, int mv_x1, int mv_y1,
                            bool quarter_pel, int bit_depth, int32_t* pred) {
  const int lists = b_pred_lists(pred_kind);
  if (lists == 1) {
    predict_motion_block(ref0, x0, y0, 16, 16, mv_x0, mv_y0, quarter_pel, bit_depth, pred);
    return;
  }
  if (lists == 2) {
    predict_motion_block(ref1, x0, y0, 16, 16, mv_x1, mv_y1, quarter_pel, bit_depth, pred);
    return;
  }
  int32_t p1[256];
  predict_motion_block(ref0, x0, y0, 16, 16, mv_x0, mv_y0, quarter_pel, bit_depth, pred);
  predict_motion_block(ref1, x0, y0, 16, 16, mv_x1, mv_y1, quarter_pel, bit_depth, p1);
  for (int i = 0; i < 256; ++i) pred[i] = (pred[i] + p1[i] + 1) >> 1;
}

// Temporal-difference prediction: the neighbours of the 4x4 block at (x0, y0) (z-order index
// `block` of macroblock (mb_x, mb_y)) taken from the difference plane
// D'(x, y) = clip(recon(x, y) - ref(x + mv_x, y + mv_y) + 2^(B-1), 0, 2^B - 1) (reference
// coordinates clamped), with the availability and substitution rules of intra prediction.
// mc(x, y) is the motion-compensated reference sample at (x, y) (motion_sample's value).
// n = 4 (a TD block) or 16 (format 1.12: a TD16 macroblock, block 0, which like I16x16 reads
// no top-right samples).
template <class MotionSample>
IntraNeighbors td_neighbors_from(const SamplePlane& recon, const MotionSample& mc, int x0, int y0,
                                 int mb_x, int mb_y, int block, int bit_depth, int n = 4) {
  const int stride = n == 16 ? n + 1 : 2 * n + 1;
  const int32_t c = 1 << (bit_depth - 1), max_value = (1 << bit_depth) - 1;
  const auto d = [&](int x, int y) -> uint16_t {
    if (x < 0 || y < 0 || x >= recon.width || y >= recon.height) return 0;
    return static_cast<uint16_t>(std::clamp(recon.at(x, y) - mc(x, y) + c, 0, max_value));
  };
  uint16_t local[17 * 17];
  for (int i = 0; i < stride; ++i) local[i] = d(x0 - 1 + i, y0 - 1);
  for (int j = 1; j <= n; ++j) local[j * stride] = d(x0 - 1, y0 - 1 + j);
  const bool top_right = n < 16 && is_coded(x0 + n, y0 - 1, recon.width, mb_x, mb_y, block);
  return make_neighbors(local, stride, 1, 1, n, y0 > 0, x0 > 0, top_right, bit_depth);
}

// The motion-compensated reference over a macroblock and the samples its TD neighbours read:
// two columns left, two rows above (the quadratic TD16 mode, format 1.13; the other TD modes
// read one) and up to 4 samples beyond the right edge, i.e. picture positions
// (16 mb_x - 2 .. 16 mb_x + 19, 16 mb_y - 2 .. 16 mb_y + 15).
struct TdWindow {
  static constexpr int kWidth = 22, kHeight = 18;
  int x0 = 0, y0 = 0;  // picture position of mc[0] (the macroblock's corner - (2, 2))
  int32_t mc[kWidth * kHeight];
  // The window of macroblock (mb_x, mb_y): sets x0, y0 (mc is the caller's to fill).
  void place(int mb_x, int mb_y) {
    x0 = mb_x * 16 - 2;
    y0 = mb_y * 16 - 2;
  }
  // motion_sample's value at picture position (x, y) inside the window.
  int32_t at(int x, int y) const { return mc[(y - y0) * kWidth + x - x0]; }
};

// Fills `w` for macroblock (mb_x, mb_y): predict(x, y, width, height, pred) writes the
// motion-compensated block at (x, y) (predict_motion_block's values, any size up to 16 x 16).
template <class PredictBlock>
void fill_td_window(int mb_x, int mb_y, const PredictBlock& predict, TdWindow& w) {
  w.place(mb_x, mb_y);
  // Tiles of at most 16 x 16: columns 0..15 and 16..21, rows 0..15 and 16..17.
  constexpr int kTiles[4][4] = {{0, 0, 16, 16}, {16, 0, 6, 16}, {0, 16, 16, 2}, {16, 16, 6, 2}};
  int32_t block[256];
  for (const auto& t : kTiles) {
    predict(w.x0 + t[0], w.y0 + t[1], t[2], t[3], block);
    for (int y = 0; y < t[3]; ++y)
      for (int x = 0; x < t[2]; ++x)
        w.mc[(t[1] + y) * TdWindow::kWidth + t[0] + x] = block[y * t[2] + x];
  }
}

// The temporal-difference prediction of the 4x4 block at (x0, y0) (z-order index `block` of
// the window's macroblock (mb_x, mb_y)): motion-compensated reference plus the intra prediction
// (mode) of the difference plane, 2^(B-1) removed; not clipped.
inline void predict_td(const SamplePlane& recon, const TdWindow& w, int x0, int y0, int mb_x,
                       int mb_y, int block, int mode, int bit_depth, int32_t* pred) {
  const IntraNeighbors nb = td_neighbors_from(
      recon, [&](int x, int y) { return w.at(x, y); }, x0, y0, mb_x, mb_y, block, bit_depth);
  int32_t pd[16];
  predict_intra(4, mode, nb, (1 << bit_depth) - 1, pd);
  const int32_t c = 1 << (bit_depth - 1);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) pred[y * 4 + x] = w.at(x0 + x, y0 + y) + pd[y * 4 + x] - c;
}

// Format 1.12 (TD16, docs/bitstream.md 4.15): the prediction of a TD16 macroblock: the
// motion-compensated reference plus the I16x16 prediction (mode 0..3, or since 1.13 the quadratic
// mode where has_quadratic_mode) of the difference plane from the macroblock's neighbours,
// 2^(B-1) removed; not clipped.
inline void predict_td16(const SamplePlane& recon, const TdWindow& w, int mb_x, int mb_y, int mode,
                         int bit_depth, int32_t* pred) {
  const int x0 = mb_x * 16, y0 = mb_y * 16;
  const int32_t c = 1 << (bit_depth - 1), max_value = (1 << bit_depth) - 1;
  int32_t pd[256];
  if (mode == kIntra16x16Quadratic) {
    // The difference plane over the two rows above and the two columns left (18 x 18, the
    // block's own samples unused).
    uint16_t local[18 * 18] = {};
    const auto d = [&](int x, int y) {
      return static_cast<uint16_t>(
          std::clamp(recon.at(x0 + x, y0 + y) - w.at(x0 + x, y0 + y) + c, 0, max_value));
    };
    for (int y = -2; y < 16; ++y)
      for (int x = -2; x < 16; ++x)
        if (y < 0 || x < 0) local[(y + 2) * 18 + x + 2] = d(x, y);
    predict_quadratic16(local, 18, 2, 2, max_value, pd);
  } else {
    const IntraNeighbors nb = td_neighbors_from(
        recon, [&](int x, int y) { return w.at(x, y); }, x0, y0, mb_x, mb_y, 0, bit_depth, 16);
    predict_intra(16, mode, nb, max_value, pd);
  }
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) pred[y * 16 + x] = w.at(x0 + x, y0 + y) + pd[y * 16 + x] - c;
}

// Neighbours of the n x n block at (x0, y0), the top-left 4x4 unit of which has z-order index
// `block` within macroblock (mb_x, mb_y).
inline IntraNeighbors block_neighbors(const SamplePlane& plane, int x0, int y0, int n, int mb_x,
                                      int mb_y, int block, int bit_depth) {
  const bool top_right = n < 16 && is_coded(x0 + n, y0 - 1, plane.width, mb_x, mb_y, block);
  return make_neighbors(plane.samples.data(), plane.width, x0, y0, n, y0 > 0, x0 > 0, top_right,
                        bit_depth);
}

// The I16x16 prediction (mode 0..3, or kIntra16x16Quadratic where has_quadratic_mode) of
// macroblock (mb_x, mb_y) from the samples of `plane` reconstructed so far.
inline void predict_i16(const SamplePlane& plane, int mb_x, int mb_y, int mode, int bit_depth,
                        int32_t* pred) {
  const int max_value = (1 << bit_depth) - 1;
  if (mode == kIntra16x16Quadratic) {
    predict_quadratic16(plane.samples.data(), plane.width, mb_x * 16, mb_y * 16, max_value, pred);
    return;
  }
  const IntraNeighbors nb =
      block_neighbors(plane, mb_x * 16, mb_y * 16, 16, mb_x, mb_y, 0, bit_depth);
  predict_intra(16, mode, nb, max_value, pred);
}

}  // namespace gvkit::codec::detail
