// Intra decoder of one plane: reads each macroblock's syntax (the mirror of write_macroblock in
// macroblock_syntax.hpp) and reconstructs it. Every decoded value is range-checked, so any byte
// string either decodes or fails with the macroblock and field named.
#include <string>
#include <vector>

#include "cross_plane_residual.hpp"
#include "deblocking_strengths.hpp"
#include "gvkit/codec/cabac_decoder.hpp"
#include "gvkit/codec/plane_coding.hpp"
#include "macroblock_syntax.hpp"

namespace gvkit::codec {
namespace {
using namespace detail;

class MacroblockReader {
 public:
  MacroblockReader(CabacDecoder& dec, ContextSet& ctx, PlaneState& st, const PlaneCodingParams& p)
      : dec_(dec), ctx_(ctx), st_(st), p_(p) {}

  Status read(int mb_x, int mb_y, MacroblockData& mb) {
    mb.cross_scale = 0;
    if (st_.bidirectional) return read_b(mb_x, mb_y, mb);
    const int mb_index = mb_y * st_.mbs_x + mb_x;
    if (st_.predicted) {
      const auto flag_ctx = [&](const std::vector<uint8_t>& v, auto pred) {
        return st_.neighbour_count(v, mb_x, mb_y, pred);
      };
      mb.shared =
          st_.can_share(mb_index) &&
          dec_.decode(ctx_.shared_mv[flag_ctx(st_.shared, [](uint8_t k) { return k != 0; })]);
      st_.shared[mb_index] = mb.shared;
      if (mb.shared ||
          dec_.decode(
              ctx_.is_inter[flag_ctx(st_.mb_type, [](uint8_t t) { return t == kMbInter; })])) {
        mb.type = kMbInter;
        st_.mb_type[mb_index] = kMbInter;
        mb.skip =
            mb.shared
                ? dec_.decode(ctx_.shared_skip[st_.colocated->skip[mb_index]])
                : dec_.decode(ctx_.skip[flag_ctx(st_.skip, [](uint8_t k) { return k != 0; })]);
        st_.skip[mb_index] = mb.skip;
        // Format 1.7, inter partitions (docs/bitstream.md 4.11).
        mb.partition = st_.partitions && !mb.skip && !mb.shared
                           ? read_partition_type(dec_, ctx_.partition)
                           : kPart16x16;
        if (mb.partition != kPart16x16) return read_partitioned(mb_x, mb_y, mb);
        // Format 1.11, merge: the skip's vector, or whether a 16x16 macroblock is merged.
        int cand[kMergeCandidates][2];
        mb.merge_idx = 0;
        if (st_.merge && !mb.shared) {
          int p0x, p0y;
          st_.mv_predictor(mb_x, mb_y, &p0x, &p0y, 0);
          const int n = st_.merge_candidates(mb_x, mb_y, p0x, p0y, cand);
          CabacContext* contexts = mb.skip ? ctx_.merge_idx : ctx_.merge_inter;
          while (mb.merge_idx < n && dec_.decode(contexts[mb.merge_idx])) ++mb.merge_idx;
        }
        const bool merged = !mb.skip && !mb.shared && mb.merge_idx > 0;
        // Format 1.6: the reference (skip: 0; shared: the co-located macroblock's).
        mb.ref_idx = mb.shared ? st_.colocated_ref(mb_index) : 0;
        if (!mb.skip && !mb.shared && !merged && p_.ref_count > 1)
          mb.ref_idx = read_ref_idx(dec_, ctx_.ref_idx, st_.ref_context(mb_x, mb_y), p_.ref_count);
        if (mb.ref_idx >= p_.ref_count)
          return corrupt_data("ref_idx " + std::to_string(mb.ref_idx) + " of the co-located " +
                              "macroblock exceeds the frame's " + std::to_string(p_.ref_count) +
                              " references");
        st_.ref_idx[mb_index] = static_cast<uint8_t>(mb.ref_idx);
        int px, py;
        if (mb.shared) {
          px = st_.colocated->mv_x[mb_index];
          py = st_.colocated->mv_y[mb_index];
        } else {
          st_.mv_predictor(mb_x, mb_y, &px, &py, mb.ref_idx);
        }
        if (!mb.shared && mb.merge_idx > 0) {
          px = cand[mb.merge_idx - 1][0];
          py = cand[mb.merge_idx - 1][1];
        }
        mb.mv_x = px;
        mb.mv_y = py;
        if (!mb.skip && !mb.shared && !merged) {
          int dx, dy;
          GVKIT_RETURN_IF_ERROR(read_mvd(0, dx));
          GVKIT_RETURN_IF_ERROR(read_mvd(1, dy));
          mb.mv_x += dx;
          mb.mv_y += dy;
          const int max_motion = p_.subpel ? 4 * kMaxMotion : kMaxMotion;
          if (std::abs(mb.mv_x) > max_motion || std::abs(mb.mv_y) > max_motion)
            return corrupt_data("motion vector out of range");
        }
        st_.mv_x[mb_index] = static_cast<int16_t>(mb.mv_x);
        st_.mv_y[mb_index] = static_cast<int16_t>(mb.mv_y);
        if (st_.partitions) st_.grid.set_macroblock(mb_x, mb_y, mb.ref_idx, mb.mv_x, mb.mv_y);
        const int gx0 = mb_x * 4, gy0 = mb_y * 4;
        mb.td = !mb.skip && p_.td_prediction &&
                dec_.decode(ctx_.td_flag[flag_ctx(st_.td, [](uint8_t k) { return k != 0; })]);
        st_.td[mb_index] = mb.td;
        mb.td16 = mb.td && p_.td16 &&  // format 1.12
                  dec_.decode(ctx_.td16[flag_ctx(st_.td16, [](uint8_t k) { return k != 0; })]);
        st_.td16[mb_index] = mb.td16;
        if (mb.td16) {
          if (has_quadratic_mode(p_, mb_x, mb_y) && dec_.decode(ctx_.td16_quadratic[0])) {
            mb.i16_mode = kIntra16x16Quadratic;  // format 1.13
          } else {
            mb.i16_mode = dec_.decode(ctx_.td16_mode[0]);
            mb.i16_mode |= dec_.decode(ctx_.td16_mode[1]) << 1;
          }
        }
        if (mb.td && !mb.td16) {
          GVKIT_RETURN_IF_ERROR(read_4x4_modes(gx0, gy0, mb));
        } else {
          for (int i = 0; i < 16; ++i) st_.mode_at(gx0 + i % 4, gy0 + i / 4) = kIntraDc;
        }
        return mb.skip ? clear_residual(mb_x, mb_y, mb) : read_cbp_and_residuals(mb_x, mb_y, mb);
      }
      st_.skip[mb_index] = 0;
      st_.td[mb_index] = 0;
      st_.td16[mb_index] = 0;
      st_.ref_idx[mb_index] = 0;
      if (st_.partitions) st_.grid.set_macroblock(mb_x, mb_y, -1, 0, 0);  // format 1.7
    }
    mb.ref_idx = 0;
    mb.partition = kPart16x16;
    return read_intra(mb_x, mb_y, mb);
  }

 private:
  // ---- Format 1.7, inter partitions: the mirror of write_partitioned_motion ----
  Status read_partitioned(int mb_x, int mb_y, MacroblockData& mb) {
    const int t = mb.partition, count = partition_count(t);
    const size_t mb_index = static_cast<size_t>(mb_y) * st_.mbs_x + mb_x;
    for (int k = 0; k < count; ++k) {
      const PartitionRect r = partition_rect(t, k);
      mb.part_ref[k] =
          p_.ref_count > 1
              ? read_ref_idx(dec_, ctx_.ref_idx,
                             st_.grid.ref_context(2 * mb_x + r.x, 2 * mb_y + r.y), p_.ref_count)
              : 0;
      st_.grid.set(mb_x, mb_y, r, mb.part_ref[k], 0, 0);
    }
    for (int k = 0; k < count; ++k) st_.grid.set(mb_x, mb_y, partition_rect(t, k), -1, 0, 0);
    const int max_motion = p_.subpel ? 4 * kMaxMotion : kMaxMotion;
    for (int k = 0; k < count; ++k) {
      int px, py, dx, dy;
      partition_mv_predictor(st_.grid, mb_x, mb_y, t, k, mb.part_ref[k], &px, &py);
      GVKIT_RETURN_IF_ERROR(read_mvd(0, dx));
      GVKIT_RETURN_IF_ERROR(read_mvd(1, dy));
      mb.part_mv_x[k] = px + dx;
      mb.part_mv_y[k] = py + dy;
      if (std::abs(mb.part_mv_x[k]) > max_motion || std::abs(mb.part_mv_y[k]) > max_motion)
        return corrupt_data("motion vector of partition " + std::to_string(k) + " out of range");
      st_.grid.set(mb_x, mb_y, partition_rect(t, k), mb.part_ref[k], mb.part_mv_x[k],
                   mb.part_mv_y[k]);
    }
    mb.ref_idx = mb.part_ref[0];
    mb.mv_x = mb.part_mv_x[0];
    mb.mv_y = mb.part_mv_y[0];
    st_.ref_idx[mb_index] = static_cast<uint8_t>(mb.ref_idx);
    st_.mv_x[mb_index] = static_cast<int16_t>(mb.mv_x);
    st_.mv_y[mb_index] = static_cast<int16_t>(mb.mv_y);
    mb.td = false;
    mb.td16 = false;
    st_.td[mb_index] = 0;
    st_.td16[mb_index] = 0;
    const int gx0 = mb_x * 4, gy0 = mb_y * 4;
    for (int i = 0; i < 16; ++i) st_.mode_at(gx0 + i % 4, gy0 + i / 4) = kIntraDc;
    return read_cbp_and_residuals(mb_x, mb_y, mb);
  }
  // ---- end of inter partitions ----

  // A skip macroblock (P or B): no residual; its 4x4 blocks and quadrants count as uncoded.
  Status clear_residual(int mb_x, int mb_y, MacroblockData& mb) {
    const int gx0 = mb_x * 4, gy0 = mb_y * 4;
    mb.cbp = 0;
    mb.transform = 4;
    for (int b = 0; b < 16; ++b) std::fill(mb.levels[b], mb.levels[b] + 16, 0);
    for (int i = 0; i < 16; ++i) st_.cbf_at(gx0 + i % 4, gy0 + i / 4) = 0;
    for (int q = 0; q < 4; ++q) st_.cbp_at(mb_x * 2 + (q & 1), mb_y * 2 + (q >> 1)) = 0;
    return Status::ok();
  }

  // B planes (format 1.5): the mirror of write_b_macroblock.
  Status read_b(int mb_x, int mb_y, MacroblockData& mb) {
    const int mb_index = mb_y * st_.mbs_x + mb_x;
    const auto flag_ctx = [&](const std::vector<uint8_t>& v, auto pred) {
      return st_.neighbour_count(v, mb_x, mb_y, pred);
    };
    mb.td = false;
    mb.td16 = false;
    mb.shared = false;
    mb.partition = kPart16x16;
    mb.skip = dec_.decode(ctx_.skip[flag_ctx(st_.skip, [](uint8_t k) { return k != 0; })]);
    st_.skip[mb_index] = mb.skip;
    st_.td[mb_index] = 0;
    st_.td16[mb_index] = 0;
    if (!mb.skip &&
        !dec_.decode(
            ctx_.is_inter[flag_ctx(st_.mb_type, [](uint8_t t) { return t == kMbInter; })])) {
      st_.lists[mb_index] = 0;
      return read_intra(mb_x, mb_y, mb);
    }
    mb.type = kMbInter;
    st_.mb_type[mb_index] = kMbInter;
    BPred pred = kBDirect;
    if (!mb.skip && !dec_.decode(ctx_.b_pred[0]))
      pred = dec_.decode(ctx_.b_pred[1]) ? kBBi : (dec_.decode(ctx_.b_pred[2]) ? kBL1 : kBL0);
    mb.b_pred = pred;
    int p0x, p0y, p1x, p1y;
    st_.mv_predictor_list(0, mb_x, mb_y, &p0x, &p0y);
    st_.mv_predictor_list(1, mb_x, mb_y, &p1x, &p1y);
    const int lists = b_pred_lists(pred);
    mb.mv_x = mb.mv_y = mb.mv_x1 = mb.mv_y1 = 0;
    if (pred == kBDirect) {
      mb.mv_x = p0x;
      mb.mv_y = p0y;
      mb.mv_x1 = p1x;
      mb.mv_y1 = p1y;
    }
    const int max_motion = p_.subpel ? 4 * kMaxMotion : kMaxMotion;
    for (int list = 0; list < 2 && pred != kBDirect; ++list) {
      if (!((lists >> list) & 1)) continue;
      int dx, dy;
      GVKIT_RETURN_IF_ERROR(read_mvd(0, dx));
      GVKIT_RETURN_IF_ERROR(read_mvd(1, dy));
      const int mx = (list ? p1x : p0x) + dx, my = (list ? p1y : p0y) + dy;
      if (std::abs(mx) > max_motion || std::abs(my) > max_motion)
        return corrupt_data(std::string("motion vector out of range (list ") + (list ? "1" : "0") +
                            ")");
      (list ? mb.mv_x1 : mb.mv_x) = mx;
      (list ? mb.mv_y1 : mb.mv_y) = my;
    }
    st_.lists[mb_index] = static_cast<uint8_t>(lists);
    st_.mv_x[mb_index] = static_cast<int16_t>(mb.mv_x);
    st_.mv_y[mb_index] = static_cast<int16_t>(mb.mv_y);
    st_.mv_x1[mb_index] = static_cast<int16_t>(mb.mv_x1);
    st_.mv_y1[mb_index] = static_cast<int16_t>(mb.mv_y1);
    const int gx0 = mb_x * 4, gy0 = mb_y * 4;
    for (int i = 0; i < 16; ++i) st_.mode_at(gx0 + i % 4, gy0 + i / 4) = kIntraDc;
    return mb.skip ? clear_residual(mb_x, mb_y, mb) : read_cbp_and_residuals(mb_x, mb_y, mb);
  }

  Status read_intra(int mb_x, int mb_y, MacroblockData& mb) {
    const int mb_index = mb_y * st_.mbs_x + mb_x;
    mb.td = false;
    mb.td16 = false;
    mb.shared = false;
    const auto neighbour_type = [&](int dx, int dy, MbType t) {
      const int x = mb_x + dx, y = mb_y + dy;
      if (x < 0 || y < 0) return 0;
      return st_.mb_type[static_cast<size_t>(y) * st_.mbs_x + x] == t ? 1 : 0;
    };
    if (dec_.decode(
            ctx_.is_i16[neighbour_type(-1, 0, kMbI16x16) + neighbour_type(0, -1, kMbI16x16)]))
      mb.type = kMbI16x16;
    else
      mb.type =
          dec_.decode(ctx_.is_8x8[neighbour_type(-1, 0, kMbI8x8) + neighbour_type(0, -1, kMbI8x8)])
              ? kMbI8x8
              : kMbI4x4;
    st_.mb_type[mb_index] = mb.type;
    const int gx0 = mb_x * 4, gy0 = mb_y * 4;
    if (mb.type == kMbI16x16) {
      if (has_quadratic_mode(p_, mb_x, mb_y) && dec_.decode(ctx_.i16_quadratic[0])) {  // 1.13
        mb.i16_mode = kIntra16x16Quadratic;
      } else {
        mb.i16_mode = dec_.decode(ctx_.i16_mode[0]);
        mb.i16_mode |= dec_.decode(ctx_.i16_mode[1]) << 1;
      }
      for (int i = 0; i < 16; ++i) st_.mode_at(gx0 + i % 4, gy0 + i / 4) = kIntraDc;
    } else if (mb.type == kMbI8x8) {
      for (int q = 0; q < 4; ++q) {
        const int gx = gx0 + (q & 1) * 2, gy = gy0 + (q >> 1) * 2;
        int mode = 0;
        GVKIT_RETURN_IF_ERROR(read_mode(most_probable_mode(st_, gx, gy, true), 9, "8x8", mode));
        mb.modes[q] = static_cast<int8_t>(mode);
        for (int i = 0; i < 4; ++i) st_.mode_at(gx + (i & 1), gy + (i >> 1)) = mb.modes[q];
      }
    } else {
      GVKIT_RETURN_IF_ERROR(read_4x4_modes(gx0, gy0, mb));
    }
    return read_cbp_and_residuals(mb_x, mb_y, mb);
  }

  Status read_mvd(int component, int& value) {
    value = 0;
    if (!dec_.decode(ctx_.mvd_zero[component])) return Status::ok();
    const bool negative = dec_.decode_bypass();
    int k = 0;
    while (dec_.decode_bypass())
      if (++k > max_mvd_escape(p_.subpel != 0))
        return corrupt_data("motion vector difference escape too long");
    uint32_t v = (1u << k) - 1;
    for (int b = k - 1; b >= 0; --b) v += static_cast<uint32_t>(dec_.decode_bypass()) << b;
    value = static_cast<int>(v) + 1;
    if (negative) value = -value;
    return Status::ok();
  }

  Status read_cbp_and_residuals(int mb_x, int mb_y, MacroblockData& mb) {
    const int gx0 = mb_x * 4, gy0 = mb_y * 4;
    mb.cbp = 0;
    const int cx0 = mb_x * 2, cy0 = mb_y * 2;
    if (st_.codes_cross_scale(mb_x, mb_y))  // format 1.6
      mb.cross_scale = read_cross_scale(dec_, ctx_.cross_scale, ctx_.cross_sign[0]);
    for (int q = 0; q < 4; ++q) {
      const int cx = cx0 + (q & 1), cy = cy0 + (q >> 1);
      const int left = cx > 0 ? st_.cbp_at(cx - 1, cy) : 0;
      const int top = cy > 0 ? st_.cbp_at(cx, cy - 1) : 0;
      const int bit = dec_.decode(ctx_.cbp[left + 2 * top]);
      mb.cbp |= static_cast<uint8_t>(bit << q);
      st_.cbp_at(cx, cy) = static_cast<uint8_t>(bit);
    }
    // Format 1.6: transform_size (docs/bitstream.md 4.8).
    int size = mb.type == kMbI8x8 ? 8 : 4;
    if (has_transform_size(mb, p_)) {
      const size_t i = static_cast<size_t>(mb_y) * st_.mbs_x + mb_x;
      const auto count = [&](int code) {
        return (mb_x > 0 && st_.transform[i - 1] >= code ? 1 : 0) +
               (mb_y > 0 && st_.transform[i - st_.mbs_x] >= code ? 1 : 0);
      };
      if (dec_.decode(ctx_.transform_size[0][count(1)]))
        size =
            p_.max_transform == 16 && mb.cbp == 15 && dec_.decode(ctx_.transform_size[1][count(2)])
                ? 16
                : 8;
    }
    mb.transform = size == 8 && mb.type == kMbI8x8 ? 4 : size;
    st_.transform[static_cast<size_t>(mb_y) * st_.mbs_x + mb_x] =
        static_cast<uint8_t>(transform_code(size));
    if (size == 16) {
      for (int i = 0; i < 16; ++i) st_.cbf_at(gx0 + i % 4, gy0 + i / 4) = 1;
      std::fill(mb.levels16, mb.levels16 + 256, 0);
      return read_residual(mb.levels16, 16);
    }
    if (size == 8) {
      for (int q = 0; q < 4; ++q) {
        const int bit = (mb.cbp >> q) & 1;
        for (int i = 0; i < 4; ++i)
          st_.cbf_at(gx0 + (q & 1) * 2 + (i & 1), gy0 + (q >> 1) * 2 + (i >> 1)) =
              static_cast<uint8_t>(bit);
        std::fill(mb.levels8[q], mb.levels8[q] + 64, 0);
        if (bit) GVKIT_RETURN_IF_ERROR(read_residual(mb.levels8[q], 8));
      }
      return Status::ok();
    }
    for (int b = 0; b < 16; ++b) {
      const int gx = gx0 + block_x(b), gy = gy0 + block_y(b);
      std::fill(mb.levels[b], mb.levels[b] + 16, 0);
      if (!((mb.cbp >> (b >> 2)) & 1)) {
        st_.cbf_at(gx, gy) = 0;
        continue;
      }
      const int left = gx > 0 ? st_.cbf_at(gx - 1, gy) : 0;
      const int top = gy > 0 ? st_.cbf_at(gx, gy - 1) : 0;
      const int coded = dec_.decode(ctx_.cbf[left + 2 * top]);
      st_.cbf_at(gx, gy) = static_cast<uint8_t>(coded);
      if (coded) GVKIT_RETURN_IF_ERROR(read_residual(mb.levels[b], 4));
    }
    return Status::ok();
  }

  // The 16 4x4 prediction modes of a macroblock whose top-left 4x4 block is (gx0, gy0) in
  // block units (intra 4x4, and the difference prediction of a TD macroblock).
  Status read_4x4_modes(int gx0, int gy0, MacroblockData& mb) {
    for (int b = 0; b < 16; ++b) {
      const int gx = gx0 + block_x(b), gy = gy0 + block_y(b);
      int mode = 0;
      GVKIT_RETURN_IF_ERROR(
          read_mode(most_probable_mode(st_, gx, gy, false), mode_count4(p_), "4x4", mode));
      mb.modes[b] = static_cast<int8_t>(mode);
      st_.mode_at(gx, gy) = mb.modes[b];
    }
    return Status::ok();
  }

  Status read_mode(int mpm, int mode_count, const char* kind, int& mode) {
    if (dec_.decode(ctx_.prev_mode_flag[0])) {
      mode = mpm;
      return Status::ok();
    }
    const int bits = mode_count > 9 ? 4 : 3;
    int rem = 0;
    for (int b = 0; b < bits; ++b) rem |= dec_.decode(ctx_.rem_mode[0]) << b;
    if (rem >= mode_count - 1)
      return corrupt_data(std::string("invalid intra ") + kind + " mode (rem_intra_pred_mode " +
                          std::to_string(rem) + ")");
    mode = rem < mpm ? rem : rem + 1;
    return Status::ok();
  }

  // On a local copy of the decoder, whose state the compiler can then keep in registers: the
  // context updates (byte stores) could otherwise alias it and force it through memory. One
  // instance per block size, so that the scan, the contexts and the loop bounds are constants.
  Status read_residual(int32_t* levels, int n) {
    CabacDecoder dec = dec_;
    const Status status = n == 4   ? read_residual_with<4>(dec, levels)
                          : n == 8 ? read_residual_with<8>(dec, levels)
                                   : read_residual_with<16>(dec, levels);
    dec_ = dec;
    return status;
  }

  template <int N>
  Status read_residual_with(CabacDecoder& dec, int32_t* levels) {
    constexpr int count = N * N, cat = N == 4 ? 0 : (N == 8 ? 1 : 2);
    const ResidualScan& scan = residual_scan<N>();
    CabacContext* const sig = ctx_.sig[cat];
    CabacContext* const last = ctx_.last[cat];
    uint16_t sig_pos[count];  // raster positions of the significant levels, in scan order
    int num_sig = 0;
    bool ended = false;
    for (int i = 0; i < count - 1; ++i) {
      const int c = scan.context[i];
      if (dec.decode(sig[c])) {
        sig_pos[num_sig++] = scan.position[i];
        if (dec.decode(last[c])) {
          ended = true;
          break;
        }
      }
    }
    if (!ended) sig_pos[num_sig++] = scan.position[count - 1];
    CabacContext* const level = ctx_.level[cat];
    int num_gt1 = 0, num_eq1 = 0;
    for (int s = num_sig - 1; s >= 0; --s) {
      uint32_t abs_minus1 = dec.decode(level[num_gt1 ? 0 : std::min(4, 1 + num_eq1)]);
      if (ctx_.adaptive_levels) {
        if (abs_minus1) {
          const int k0 = adaptive_order(ctx_.level_mean16[cat]);
          int k = k0;
          while (dec.decode_bypass())
            if (++k > 24) return corrupt_data("residual level escape longer than 24 bits");
          uint32_t value = (1u << k) - (1u << k0), tail = 0;
          for (int b = k - 1; b >= 0; --b) tail |= static_cast<uint32_t>(dec.decode_bypass()) << b;
          abs_minus1 = 1 + value + tail;
          if (abs_minus1 >= static_cast<uint32_t>(kMaxAbsLevel))
            return corrupt_data("residual level out of range");
        }
        update_level_mean(ctx_.level_mean16[cat], abs_minus1);
      } else if (abs_minus1) {
        CabacContext& c = level[5 + std::min(4, num_gt1)];
        while (abs_minus1 < static_cast<uint32_t>(kLevelPrefixMax) && dec.decode(c)) ++abs_minus1;
        if (abs_minus1 == static_cast<uint32_t>(kLevelPrefixMax)) {
          int k = 0;
          while (dec.decode_bypass()) {
            if (++k > 24) return corrupt_data("residual level escape longer than 24 bits");
          }
          uint32_t suffix = (1u << k) - 1, tail = 0;
          for (int b = k - 1; b >= 0; --b) tail |= static_cast<uint32_t>(dec.decode_bypass()) << b;
          abs_minus1 += suffix + tail;
          if (abs_minus1 >= static_cast<uint32_t>(kMaxAbsLevel))
            return corrupt_data("residual level out of range");
        }
      }
      const int32_t magnitude = static_cast<int32_t>(abs_minus1) + 1;
      levels[sig_pos[s]] = dec.decode_bypass() ? -magnitude : magnitude;
      if (abs_minus1 == 0)
        ++num_eq1;
      else
        ++num_gt1;
    }
    return Status::ok();
  }

  CabacDecoder& dec_;
  ContextSet& ctx_;
  PlaneState& st_;
  const PlaneCodingParams& p_;
};

void reconstruct_macroblock(SamplePlane& plane, int mb_x, int mb_y, const MacroblockData& mb,
                            const PlaneCodingParams& p, const SamplePlane* reference0,
                            const SamplePlane* reference1,
                            const std::vector<const SamplePlane*>* more_references,
                            const CrossPlaneResidual* cross) {
  const int max_value = (1 << p.bit_depth) - 1;
  // P planes: the macroblock's own reference (format 1.6).
  const SamplePlane* reference =
      mb.type == kMbInter && mb.ref_idx > 0 ? (*more_references)[mb.ref_idx - 1] : reference0;
  int32_t pred[256];
  // Format 1.6: the cross-plane term joins the prediction of each block (so of what I4x4 and
  // I8x8 blocks predict the next block from).
  const auto add_cross = [&](int x0, int y0, int n) {
    if (mb.cross_scale) add_cross_plane_term(mb.cross_scale, *cross, x0, y0, n, pred);
  };
  if (mb.type == kMbInter && reference1) {
    predict_b_inter(*reference, *reference1, mb_x * 16, mb_y * 16, mb.b_pred, mb.mv_x, mb.mv_y,
                    mb.mv_x1, mb.mv_y1, p.subpel != 0, p.bit_depth, pred);
    add_cross(mb_x * 16, mb_y * 16, 16);
    reconstruct_macroblock_residual(pred, mb, p, plane.samples.data(), plane.width, mb_x * 16,
                                    mb_y * 16);
  } else if (mb.type == kMbInter && mb.td) {
    TdWindow window;
    fill_td_window(
        mb_x, mb_y,
        [&](int x, int y, int w, int h, int32_t* out) {
          predict_motion_block(*reference, x, y, w, h, mb.mv_x, mb.mv_y, p.subpel != 0, p.bit_depth,
                               out);
        },
        window);
    if (mb.td16) {  // format 1.12: one 16x16 prediction, the residual of a plain inter MB
      predict_td16(plane, window, mb_x, mb_y, mb.i16_mode, p.bit_depth, pred);
      add_cross(mb_x * 16, mb_y * 16, 16);
      reconstruct_macroblock_residual(pred, mb, p, plane.samples.data(), plane.width, mb_x * 16,
                                      mb_y * 16);
      return;
    }
    for (int b = 0; b < 16; ++b) {
      const int x0 = mb_x * 16 + block_x(b) * 4, y0 = mb_y * 16 + block_y(b) * 4;
      predict_td(plane, window, x0, y0, mb_x, mb_y, b, mb.modes[b], p.bit_depth, pred);
      add_cross(x0, y0, 4);
      reconstruct_block(4, pred, mb.levels[b], p, plane.samples.data(), plane.width, x0, y0);
    }
  } else if (mb.type == kMbI16x16 || mb.type == kMbInter) {
    if (mb.type == kMbInter && mb.partition != kPart16x16) {  // format 1.7
      predict_partitions(
          mb, mb_x * 16, mb_y * 16, p.subpel != 0, p.bit_depth,
          [&](int ref) -> const SamplePlane& {
            return ref > 0 ? *(*more_references)[ref - 1] : *reference0;
          },
          pred);
    } else if (mb.type == kMbInter) {
      predict_inter(*reference, mb_x * 16, mb_y * 16, mb.mv_x, mb.mv_y, p.subpel != 0, p.bit_depth,
                    pred);
    } else {
      predict_i16(plane, mb_x, mb_y, mb.i16_mode, p.bit_depth, pred);
    }
    add_cross(mb_x * 16, mb_y * 16, 16);
    reconstruct_macroblock_residual(pred, mb, p, plane.samples.data(), plane.width, mb_x * 16,
                                    mb_y * 16);
  } else if (mb.type == kMbI8x8) {
    for (int q = 0; q < 4; ++q) {
      const int x0 = mb_x * 16 + (q & 1) * 8, y0 = mb_y * 16 + (q >> 1) * 8;
      const IntraNeighbors nb = block_neighbors(plane, x0, y0, 8, mb_x, mb_y, q * 4, p.bit_depth);
      predict_intra(8, mb.modes[q], nb, max_value, pred);
      add_cross(x0, y0, 8);
      reconstruct_block(8, pred, mb.levels8[q], p, plane.samples.data(), plane.width, x0, y0);
    }
  } else {
    for (int b = 0; b < 16; ++b) {
      const int x0 = mb_x * 16 + block_x(b) * 4, y0 = mb_y * 16 + block_y(b) * 4;
      const IntraNeighbors nb = block_neighbors(plane, x0, y0, 4, mb_x, mb_y, b, p.bit_depth);
      predict_intra(4, mb.modes[b], nb, max_value, pred);
      add_cross(x0, y0, 4);
      reconstruct_block(4, pred, mb.levels[b], p, plane.samples.data(), plane.width, x0, y0);
    }
  }
}

}  // namespace

namespace {

Result<SamplePlane> decode_plane_impl(std::string_view bytes, int width, int height,
                                      const PlaneCodingParams& params, const SamplePlane* reference,
                                      const MotionField* shared, MotionField* motion_out,
                                      const SamplePlane* reference1,
                                      const std::vector<const SamplePlane*>* more_references,
                                      const CrossPlaneLinks* cross) {
  GVKIT_CHECK(width > 0 && height > 0 && width % 16 == 0 && height % 16 == 0);
  GVKIT_CHECK(params.ref_count >= 1 && params.ref_count <= 5);
  GVKIT_CHECK(params.ref_count == 1 ||
              (reference && !reference1 && more_references &&
               more_references->size() + 1 >= static_cast<size_t>(params.ref_count)));
  if (params.ref_count > 1)
    for (int k = 0; k + 1 < params.ref_count; ++k)
      GVKIT_CHECK((*more_references)[k]->width == width && (*more_references)[k]->height == height);
  GVKIT_CHECK(!reference || (reference->width == width && reference->height == height));
  GVKIT_CHECK(!reference1 ||
              (reference && reference1->width == width && reference1->height == height && !shared));
  SamplePlane plane;
  plane.width = width;
  plane.height = height;
  plane.samples.assign(static_cast<size_t>(width) * height, 0);
  PlaneState st(width, height);
  st.predicted = reference != nullptr;
  st.bidirectional = reference1 != nullptr;
  if (params.partitions && reference && !reference1) st.enable_partitions();  // format 1.7
  st.merge = params.merge && reference && !reference1;                        // format 1.11
  st.use_reference_motion(cross ? cross->reference_motion : nullptr);
  if (reference && shared) {
    GVKIT_CHECK(shared->mbs_x == st.mbs_x && shared->mbs_y == st.mbs_y,
                "shared motion of another macroblock grid");
    st.colocated = shared;
  }
  const CrossPlaneResidual* cross_source = cross ? cross->source : nullptr;
  CrossPlaneResidual* residual_out = cross ? cross->residual_out : nullptr;
  if (cross_source) {
    GVKIT_CHECK(cross_source->width == width && cross_source->height == height,
                "cross-plane source residual of another size");
    st.cross = cross_source;
  }
  if (residual_out) residual_out->reset(width, height);
  ContextSet ctx{};
  ctx.adaptive_levels = params.adaptive_levels;
  if (st.partitions) init_partition_contexts(ctx.partition);  // format 1.7
  // Format 1.7: the X plane's final context states are the initial ones of Y and Z.
  if (cross && cross->contexts) {
    if (cross->contexts->contexts.size() != kContextSetContexts)
      return corrupt_data("cross-plane contexts: the X plane's context states are missing");
    import_context_states(*cross->contexts, ctx);
  }
  CabacDecoder decoder(bytes);
  MacroblockReader reader(decoder, ctx, st, params);
  MacroblockData mb;
  for (int mb_y = 0; mb_y < st.mbs_y; ++mb_y)
    for (int mb_x = 0; mb_x < st.mbs_x; ++mb_x) {
      const auto where = [&] {
        return "macroblock (" + std::to_string(mb_x) + ", " + std::to_string(mb_y) + ")";
      };
      const Status status = reader.read(mb_x, mb_y, mb);
      if (!status.is_ok()) return status.with_context(where());
      if (decoder.overrun()) return corrupt_data(where() + ": CABAC data ends early");
      reconstruct_macroblock(plane, mb_x, mb_y, mb, params, reference, reference1, more_references,
                             cross_source);
      if (residual_out)
        record_macroblock_residual(*residual_out, mb_x, mb_y, mb, params, cross_source);
    }
  if ((params.end_of_plane_bin && !decoder.decode_terminate()) || decoder.overrun())
    return corrupt_data("end of plane marker missing (CABAC data inconsistent)");
  deblock_coded_plane(plane, st, params);  // format 1.8
  if (reference && motion_out) st.export_motion(*motion_out);
  if (cross && cross->contexts_out) export_context_states(ctx, *cross->contexts_out);  // 1.7
  return plane;
}

}  // namespace

Result<SamplePlane> decode_plane(std::string_view bytes, int width, int height,
                                 const PlaneCodingParams& params, const SamplePlane* reference,
                                 const MotionField* shared, MotionField* motion_out,
                                 const std::vector<const SamplePlane*>* more_references,
                                 const CrossPlaneLinks* cross) {
  return decode_plane_impl(bytes, width, height, params, reference, shared, motion_out, nullptr,
                           more_references, cross);
}

Result<SamplePlane> decode_b_plane(std::string_view bytes, int width, int height,
                                   const PlaneCodingParams& params, const SamplePlane& reference0,
                                   const SamplePlane& reference1, const CrossPlaneLinks* cross) {
  PlaneCodingParams p = params;
  p.ref_count = 1;
  p.partitions = false;  // format 1.7: P planes only
  return decode_plane_impl(bytes, width, height, p, &reference0, nullptr, nullptr, &reference1,
                           nullptr, cross);
}

}  // namespace gvkit::codec
