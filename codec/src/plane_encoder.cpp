// Intra encoder of one plane: per macroblock, every candidate type (I16x16, I8x8, I4x4) is tried
// with its best modes, chosen by rate-distortion cost (SSD + lambda * estimated CABAC bits) or,
// in the fast path, by SATD plus a mode-bit penalty; the winner is written with CABAC.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <optional>

#include "cross_plane_residual.hpp"
#include "deblocking_strengths.hpp"
#include "gvkit/codec/block_distortion.hpp"
#include "gvkit/codec/cabac_encoder.hpp"
#include "gvkit/codec/interpolation_cache.hpp"
#include "gvkit/codec/motion_search.hpp"
#include "gvkit/codec/partition_search.hpp"
#include "gvkit/codec/plane_coding.hpp"
#include "macroblock_syntax.hpp"
#include "rdo_quantization.hpp"

namespace gvkit::codec {
namespace {
using namespace detail;

// Weight of the motion bits in the lossy motion search, in units of the SATD lambda: the vectors
// of a geometry video mostly fit value changes rather than motion, and a dearer vector keeps the
// field smooth and cheap (ICT face, 30 frames, fast preset: 2 gives -2.3 %, 4 gives -2.9 %
// BD-rate against 1).
constexpr double kMotionLambdaScale = 4.0;

// RDO quantization's lambda in units of the mode decision's: on the ICT face (fast preset, RDO
// quantization in every candidate) 0.5 gave -5.7 % BD-rate against the fixed offsets, the mode
// decision's own lambda -3.3 % (0.3: -5.3 %, 0.45: -5.9 %, 0.6: -5.5 %, 1.5: +0.5 %); a scale
// per frame type gained under 0.05 % (docs/benchmarks.md, RDO quantization).
constexpr double kRdoqLambdaScale = 0.5;

// An inter candidate at a given vector instead of the motion search's (kGiven: a vector and
// reference found before: another reference's search, format 1.6, or the candidate coded again
// with a cross-plane scale; kMerge: a merge candidate's vector on reference 0, format 1.11).
enum class Forced { kNone, kShared, kPredictor, kGiven, kMerge };

class MacroblockEncoder {
 public:
  MacroblockEncoder(const SamplePlane& source, SamplePlane& recon, PlaneState& st,
                    const PlaneCodingParams& p, const SamplePlane* reference,
                    const JointSearchPlanes* joint, const SamplePlane* reference1 = nullptr,
                    const std::vector<const SamplePlane*>* more_references = nullptr,
                    const CrossPlaneResidual* cross = nullptr,
                    ReferenceInterpolationCache* cache = nullptr)
      : src_(source),
        recon_(recon),
        st_(st),
        p_(p),
        ref_(reference),
        cross_(cross),
        max_value_((1 << p.bit_depth) - 1) {
    // Half-sample planes over the search area (the predictor's vector may reach further: the
    // interpolation then falls back to the plain block-wise path), from the encoder's cache when
    // it has one.
    const int margin = p.search_range + 4;
    const auto interpolate = [&](const SamplePlane& plane) {
      return cache ? cache->get(plane, p.bit_depth, margin)
                   : std::make_shared<const InterpolatedReference>(plane, p.bit_depth, margin);
    };
    if (reference) interp_ = interpolate(*reference);
    if (reference1) interp1_ = interpolate(*reference1);
    if (reference && joint) {
      joint_interp_.reserve(joint->references.size());
      for (size_t j = 0; j < joint->references.size(); ++j) {
        joint_interp_.push_back(interpolate(*joint->references[j]));
        joint_planes_.push_back({joint->sources[j], joint_interp_.back().get()});
      }
    }
    // Multiple reference frames (format 1.6): references 1 .. ref_count - 1 and, under joint
    // search, the other planes' references of the same index.
    const int more = reference && !reference1 ? p.ref_count - 1 : 0;
    more_interp_.reserve(more);
    for (int k = 0; k < more; ++k) more_interp_.push_back(interpolate(*(*more_references)[k]));
    if (more > 0 && joint && !joint->references.empty()) {
      more_joint_interp_.reserve(static_cast<size_t>(more) * joint->sources.size());
      more_joint_planes_.resize(more);
      for (int k = 0; k < more; ++k)
        for (size_t j = 0; j < joint->sources.size(); ++j) {
          more_joint_interp_.push_back(interpolate(*joint->more_references[k][j]));
          more_joint_planes_[k].push_back({joint->sources[j], more_joint_interp_.back().get()});
        }
    }
    if (p.lossless && p.near_lossless > 0) {
      // As H.264's lambda for a quantizer of the same step (0.85 2^((QP-12)/3) = 0.136 step^2).
      const double step = 2.0 * p.near_lossless + 1.0;
      lambda_ = 0.136 * step * step;
      lambda_sad_ = std::sqrt(lambda_);
    } else if (p.lossless) {
      lambda_ = 1.0;
      lambda_sad_ = 1.0;
    } else {
      lambda_ = 0.85 * std::pow(2.0, (p.qp_prime - 12) / 3.0);
      lambda_sad_ = std::sqrt(lambda_);
    }
    rdoq_lambda_ = lambda_ * kRdoqLambdaScale;
  }

  MacroblockData encode(int mb_x, int mb_y, const ContextSet& ctx) {
    mb_x_ = mb_x;
    mb_y_ = mb_y;
    partition_memo_.clear();
    own_.fill(Searched{});
    cur_ref_ = 0;
    if (ref_) {  // the skip vector and (format 1.11) the merge candidates, for every candidate
      st_.mv_predictor(mb_x, mb_y, &skip_mv_x_, &skip_mv_y_, 0);
      merge_count_ =
          st_.merge ? st_.merge_candidates(mb_x, mb_y, skip_mv_x_, skip_mv_y_, merge_cand_) : 0;
    }
    Candidate best;
    const auto consider = [&](MbType type, bool td = false, Forced forced = Forced::kNone) {
      consider_candidate(&best, ctx, [&](MacroblockData& mb, ContextSet& trial) {
        mb.type = type;
        return td                  ? try_td(mb, trial)
               : type == kMbInter  ? try_inter(mb, trial, forced)
               : type == kMbI16x16 ? try_i16(mb, trial)
                                   : (type == kMbI8x8 ? try_i8(mb, trial) : try_i4(mb, trial));
      });
    };
    const size_t mb_index = static_cast<size_t>(mb_y) * st_.mbs_x + mb_x;
    // Inter: the co-located first-plane vector (shared motion: one flag, no difference), the
    // predicted vector (H.264's P-skip check), then the plane's own search (which may land on
    // either). Fast preset: a skip macroblock (no residual) is taken at once.
    const auto skip_found = [&] { return !p_.rdo && best.mb.skip; };
    if (ref_ && st_.can_share(mb_index)) consider(kMbInter, false, Forced::kShared);
    if (ref_ && p_.skip_check && !skip_found()) consider(kMbInter, false, Forced::kPredictor);
    // Format 1.11, merge: the neighbours' vectors, each as a candidate (a skip or a merged
    // macroblock with a residual).
    for (merge_k_ = 1; ref_ && merge_k_ <= merge_count_ && !skip_found(); ++merge_k_)
      consider(kMbInter, false, Forced::kMerge);
    if (ref_ && !(p_.skip_check && skip_found())) {
      consider(kMbInter);
      own_[0] = {mv_x_, mv_y_, whole_mv_x_, whole_mv_y_, last_cost_};
    }
    // Format 1.6: the other references (fast preset: only when reference 0 gave no skip, and
    // only the one whose searched vector is cheapest by SATD + lambda * bits is coded).
    if (ref_ && p_.ref_count > 1 && !skip_found()) consider_more_references(best, ctx);
    const bool early_skip = ref_ && skip_found();
    if (!early_skip) {
      if (ref_ && st_.partitions) consider_partitions(best, ctx);  // format 1.7
      if (ref_ && p_.td_prediction) {
        // TD at the reference whose own-search candidate was cheapest (ties: the nearest).
        int td_ref = 0;
        for (int k = 1; k < p_.ref_count; ++k)
          if (own_[k].cost < own_[td_ref].cost) td_ref = k;
        cur_ref_ = td_ref;
        mv_x_ = own_[td_ref].mv_x;
        mv_y_ = own_[td_ref].mv_y;
        whole_mv_x_ = own_[td_ref].whole_x;
        whole_mv_y_ = own_[td_ref].whole_y;
        consider(kMbInter, true);
        // The sub-sample vector suits plain inter prediction; the temporal difference from a
        // whole-sample vector is often smoother, so TD also tries the whole-sample search result
        // (lossy fast preset: only with td_whole_retry, when TD with the sub-sample vector beat
        // plain inter).
        if ((p_.lossless || p_.rdo || (p_.td_whole_retry && best.mb.td)) &&
            (mv_x_ != whole_mv_x_ || mv_y_ != whole_mv_y_)) {
          mv_x_ = whole_mv_x_;
          mv_y_ = whole_mv_y_;
          consider(kMbInter, true);
        }
        if (p_.td16) consider_td16(best, ctx, td_ref);
      }
      consider(kMbI16x16);
      if (p_.allow_8x8) consider(kMbI8x8);
      consider(kMbI4x4);
    }
    // Cross-plane prediction first (its retries code 4x4 residuals in the fast preset), then the
    // fast preset's transform size for the chosen candidate (with its cross-plane term).
    try_cross_plane(&best, ctx);
    if (!p_.rdo) choose_transform_size(best, ctx);
    restore(best);
    return best.mb;
  }

  // A macroblock of a B plane: direct (taken at once by the fast preset when it needs no
  // residual, i.e. is a skip), then list 0, list 1 and bi with each list's searched vector,
  // then the intra types; the cheapest wins (the same costs as in P planes).
  MacroblockData encode_b(int mb_x, int mb_y, const ContextSet& ctx) {
    mb_x_ = mb_x;
    mb_y_ = mb_y;
    Candidate best;
    const auto consider = [&](const auto& try_candidate) {
      consider_candidate(&best, ctx, try_candidate);
    };
    int p0x, p0y, p1x, p1y;
    st_.mv_predictor_list(0, mb_x, mb_y, &p0x, &p0y);
    st_.mv_predictor_list(1, mb_x, mb_y, &p1x, &p1y);
    consider([&](MacroblockData& mb, ContextSet& trial) {
      return try_b_inter(mb, trial, kBDirect, p0x, p0y, p1x, p1y);
    });
    if (p_.rdo || !best.mb.skip) {
      const MotionSearchResult f0 = search_list(*interp_, p0x, p0y);
      const MotionSearchResult f1 = search_list(*interp1_, p1x, p1y);
      consider([&](MacroblockData& mb, ContextSet& trial) {
        return try_b_inter(mb, trial, kBL0, f0.mv_x, f0.mv_y, 0, 0);
      });
      consider([&](MacroblockData& mb, ContextSet& trial) {
        return try_b_inter(mb, trial, kBL1, 0, 0, f1.mv_x, f1.mv_y);
      });
      consider([&](MacroblockData& mb, ContextSet& trial) {
        return try_b_inter(mb, trial, kBBi, f0.mv_x, f0.mv_y, f1.mv_x, f1.mv_y);
      });
      consider([&](MacroblockData& mb, ContextSet& trial) {
        mb.type = kMbI16x16;
        return try_i16(mb, trial);
      });
      if (p_.allow_8x8)
        consider([&](MacroblockData& mb, ContextSet& trial) {
          mb.type = kMbI8x8;
          return try_i8(mb, trial);
        });
      consider([&](MacroblockData& mb, ContextSet& trial) {
        mb.type = kMbI4x4;
        return try_i4(mb, trial);
      });
    }
    // Cross-plane prediction first (its retries code 4x4 residuals in the fast preset), then the
    // fast preset's transform size for the chosen candidate (with its cross-plane term).
    try_cross_plane(&best, ctx);
    if (!p_.rdo) choose_transform_size(best, ctx);
    restore(best);
    return best.mb;
  }

 private:
  // The cheapest candidate of the current macroblock so far and its reconstructed samples.
  struct Candidate {
    MacroblockData mb;
    double cost = std::numeric_limits<double>::infinity();
    std::array<uint16_t, 256> recon;
  };

  // Codes one candidate (try_candidate(mb, contexts) writes recon_ and returns its cost; it may
  // stop once its cost reaches bound_, the best cost so far) on a copy of the contexts, and keeps
  // it in *best when it is cheaper.
  template <class Try>
  void consider_candidate(Candidate* best, const ContextSet& ctx, const Try& try_candidate) {
    Candidate c;
    ContextSet trial = ctx;
    bound_ = best->cost - extra_cost_;
    deferred_ = Deferred::kNone;
    c.cost = try_candidate(c.mb, trial) + extra_cost_;
    c.mb.cross_scale = alpha_;
    const bool kept = c.cost < best->cost;
    if (kept && deferred_ != Deferred::kNone) complete_deferred_residual(c.mb, trial);
    deferred_ = Deferred::kNone;
    if (kept) {
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
          c.recon[y * 16 + x] = recon_.at(mb_x_ * 16 + x, mb_y_ * 16 + y);
      *best = c;
    }
  }

  // Cross-plane prediction (format 1.6, Y and Z planes): where the macroblock codes a scale, the
  // least-squares scale of the chosen candidate's residual (its coded residual plus the
  // remaining error) against the source plane's; the chosen type (same vector, modes searched
  // again) is coded again with that scale, and in the slow preset also with its nonzero
  // neighbours in kCrossScales; each cost counts the scale's bins, and the cheapest is kept.
  // The fast preset's costs are SATD-based, so it keeps the scale when it lowers the SATD cost.
  void try_cross_plane(Candidate* best, const ContextSet& ctx) {
    if (!st_.codes_cross_scale(mb_x_, mb_y_) || (best->mb.type == kMbInter && best->mb.skip))
      return;
    int32_t r[256];
    macroblock_residual(best->mb, p_, r);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x)
        r[y * 16 + x] +=
            static_cast<int32_t>(src_.at(mb_x_ * 16 + x, mb_y_ * 16 + y)) - best->recon[y * 16 + x];
    const int fit = least_squares_cross_scale(r, *cross_, mb_x_, mb_y_);
    if (fit == 0) return;
    const double lambda = p_.rdo ? lambda_ : lambda_sad_;
    const auto scale_bits = [&](int alpha) {
      CabacBitCounter counter;
      ContextSet scratch = ctx;
      write_cross_scale(counter, scratch.cross_scale, scratch.cross_sign[0], alpha);
      return counter.bits();
    };
    best->cost += lambda * scale_bits(0);
    const MacroblockData base = best->mb;
    const auto retry = [&](MacroblockData& mb, ContextSet& trial) {
      mb.type = base.type;
      if (st_.bidirectional && base.type == kMbInter)
        return try_b_inter(mb, trial, base.b_pred, base.mv_x, base.mv_y, base.mv_x1, base.mv_y1);
      if (base.type == kMbInter && base.partition != kPart16x16)  // format 1.7: same motion
        return try_partitions(mb, trial, base.partition, &base);
      // P planes: the same vector on the same reference (format 1.6, several references).
      if (base.type == kMbInter && base.td) {
        cur_ref_ = base.ref_idx;
        mv_x_ = base.mv_x;
        mv_y_ = base.mv_y;
        return base.td16 ? try_td16(mb, trial) : try_td(mb, trial);
      }
      if (base.type == kMbInter) {
        const int unit = p_.subpel != 0 ? 4 : 1;
        given_ = {base.mv_x, base.mv_y, base.mv_x / unit * unit, base.mv_y / unit * unit};
        given_ref_ = base.ref_idx;
        return try_inter(mb, trial, Forced::kGiven);
      }
      return base.type == kMbI16x16
                 ? try_i16(mb, trial)
                 : (base.type == kMbI8x8 ? try_i8(mb, trial) : try_i4(mb, trial));
    };
    int scales[3], count = 0;
    scales[count++] = fit;
    if (p_.rdo) {
      const int i = cross_scale_index(fit);
      if (i > 0 && kCrossScales[i - 1] != 0) scales[count++] = kCrossScales[i - 1];
      if (i + 1 < kCrossScaleCount && kCrossScales[i + 1] != 0)
        scales[count++] = kCrossScales[i + 1];
    }
    for (int k = 0; k < count; ++k) {
      alpha_ = scales[k];
      extra_cost_ = lambda * scale_bits(alpha_);
      consider_candidate(best, ctx, retry);
    }
    alpha_ = 0;
    extra_cost_ = 0;
  }

  // The current candidate's cross-plane term added to an n x n prediction at (x0, y0).
  void add_cross(int n, int x0, int y0, int32_t* pred) const {
    if (alpha_) add_cross_plane_term(alpha_, *cross_, x0, y0, n, pred);
  }

  // ---- Larger transforms (format 1.6), fast preset ----
  // The fast preset codes its candidates' residuals as 4x4 blocks and decides the transform size
  // once, for the chosen candidate when it is a plain inter or I16x16 MB with a residual: the
  // residual is coded again by code_residual_sizes (4x4 or max_transform, by SSD + lambda x
  // bits); a P or B candidate that then has no residual at the skip vector becomes a skip.
  void choose_transform_size(Candidate& best, const ContextSet& ctx) {
    MacroblockData& mb = best.mb;
    if (p_.max_transform <= 4 || p_.lossless || mb.skip || (mb.td && !mb.td16) ||
        (mb.type != kMbInter && mb.type != kMbI16x16))
      return;
    const int x0 = mb_x_ * 16, y0 = mb_y_ * 16;
    int32_t pred[256];
    if (mb.td16) {  // format 1.12
      fill_td_window_at(mb.ref_idx, mb.mv_x, mb.mv_y);
      predict_td16(recon_, td_window_, mb_x_, mb_y_, mb.i16_mode, p_.bit_depth, pred);
    } else if (mb.type == kMbI16x16) {
      predict_i16(recon_, mb_x_, mb_y_, mb.i16_mode, p_.bit_depth, pred);
    } else if (st_.bidirectional) {
      b_prediction(mb.b_pred, mb.mv_x, mb.mv_y, mb.mv_x1, mb.mv_y1, pred);
    } else if (mb.partition != kPart16x16) {
      partition_prediction(mb, pred);  // format 1.7
    } else {
      interp(mb.ref_idx).predict(x0, y0, 16, 16, mb.mv_x, mb.mv_y, p_.subpel != 0, pred);
    }
    // Cross-plane prediction (format 1.6): the candidate's term joins the prediction.
    if (mb.cross_scale) add_cross_plane_term(mb.cross_scale, *cross_, x0, y0, 16, pred);
    ContextSet trial = ctx;
    code_residual_sizes(mb, pred, trial, mb.type == kMbInter);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) best.recon[y * 16 + x] = recon_.at(x0 + x, y0 + y);
    if (mb.type == kMbInter && mb.cbp == 0 && mb.cross_scale == 0 && mb.partition == kPart16x16 &&
        !mb.td) {
      // A skip predicts from reference 0 at the predictor (format 1.6, section 4.7) or, with
      // merge (1.11), at a neighbour's vector.
      const int idx =
          st_.bidirectional || mb.shared ? -1 : skip_index(mb.mv_x, mb.mv_y, mb.ref_idx);
      mb.skip = st_.bidirectional ? mb.b_pred == kBDirect : mb.shared || idx >= 0;
      if (mb.skip && !st_.bidirectional) mb.merge_idx = std::max(idx, 0);
    }
  }
  // ---- end of larger transforms ----

  // Puts the chosen candidate's samples back into recon_ (later candidates overwrote them).
  void restore(const Candidate& best) {
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x)
        recon_.at(mb_x_ * 16 + x, mb_y_ * 16 + y) = best.recon[y * 16 + x];
  }

  // The plane's motion search settings: full search in the slow preset, diamond in the fast one.
  MotionSearchParams motion_search_params() const {
    MotionSearchParams search;
    search.pattern = p_.rdo ? MotionSearchPattern::kFull : MotionSearchPattern::kDiamond;
    search.range = p_.search_range;
    search.subpel = p_.subpel;
    search.lossless = p_.lossless;
    search.lambda = p_.lossless ? 1.0 : kMotionLambdaScale * lambda_sad_;
    search.max_abs_mv = 4 * kMaxMotion;
    return search;
  }

  // The motion search of a P macroblock against reference `ref` around the predictor (px, py).
  MotionSearchResult search_reference(int ref, int px, int py) const {
    MotionSearchParams search = motion_search_params();
    set_shared(search, ref);
    if (ref == 0)
      search.joint = joint_planes_;
    else if (!more_joint_planes_.empty())
      search.joint = more_joint_planes_[ref - 1];
    return search_motion_16x16(src_, interp(ref), mb_x_ * 16, mb_y_ * 16, px, py, search);
  }

  // Format 1.6: the motion search on references 1 .. ref_count - 1. Slow preset: each result is
  // a candidate decided by RDO (ref_idx bits included); fast preset: the results are compared
  // by SATD + lambda * (motion + ref_idx bits), and only the cheapest one is coded as a
  // candidate, when it beats the best so far by that measure.
  void consider_more_references(Candidate& best, const ContextSet& ctx) {
    int chosen = -1;
    double chosen_cost = best.cost;
    for (int k = 1; k < p_.ref_count; ++k) {
      int px, py;
      st_.mv_predictor(mb_x_, mb_y_, &px, &py, k);
      const MotionSearchResult found = search_reference(k, px, py);
      own_[k] = {found.mv_x, found.mv_y, found.whole_mv_x, found.whole_mv_y,
                 std::numeric_limits<double>::infinity()};
      given_ = own_[k];
      given_ref_ = k;
      if (p_.rdo) {
        consider_candidate(&best, ctx, [&](MacroblockData& mb, ContextSet& trial) {
          mb.type = kMbInter;
          return try_inter(mb, trial, Forced::kGiven);
        });
        own_[k].cost = last_cost_;
        continue;
      }
      int32_t pred[256];
      interp(k).predict(mb_x_ * 16, mb_y_ * 16, 16, 16, found.mv_x, found.mv_y, p_.subpel != 0,
                        pred);
      const bool shared = is_shared_vector(found.mv_x, found.mv_y, k);
      const double bits =
          motion_bits(found.mv_x, found.mv_y, px, py, k) + (shared ? 0 : ref_idx_bits(ctx, k));
      own_[k].cost = static_cast<double>(distortion_estimate(16, pred, mb_x_ * 16, mb_y_ * 16)) +
                     lambda_sad_ * bits;
      if (own_[k].cost < chosen_cost) {
        chosen = k;
        chosen_cost = own_[k].cost;
      }
    }
    if (chosen < 0) return;
    given_ = own_[chosen];
    given_ref_ = chosen;
    consider_candidate(&best, ctx, [&](MacroblockData& mb, ContextSet& trial) {
      mb.type = kMbInter;
      return try_inter(mb, trial, Forced::kGiven);
    });
  }

  // Estimated CABAC bits of ref_idx `ref` with the current contexts (0 with one reference).
  double ref_idx_bits(const ContextSet& ctx, int ref) const {
    if (p_.ref_count <= 1) return 0.0;
    return detail::ref_idx_bits(ctx.ref_idx, st_.ref_context(mb_x_, mb_y_), ref, p_.ref_count);
  }

  // P planes: the interpolated reference `ref` (0 = the nearest).
  const InterpolatedReference& interp(int ref) const {
    return ref == 0 ? *interp_ : *more_interp_[ref - 1];
  }

  // B planes: the motion search of one list around its predictor (px, py).
  MotionSearchResult search_list(const InterpolatedReference& ref, int px, int py) const {
    MotionSearchParams search = motion_search_params();
    return search_motion_16x16(src_, ref, mb_x_ * 16, mb_y_ * 16, px, py, search);
  }

  // B planes: the prediction of kind `kind` with the list 0 vector (m0x, m0y) and the list 1
  // vector (m1x, m1y).
  void b_prediction(BPred kind, int m0x, int m0y, int m1x, int m1y, int32_t* pred) const {
    const int x0 = mb_x_ * 16, y0 = mb_y_ * 16;
    const bool qpel = p_.subpel != 0;
    const int lists = b_pred_lists(kind);
    int32_t pred1[256];
    if (lists & 1) interp_->predict(x0, y0, 16, 16, m0x, m0y, qpel, pred);
    if (lists & 2) interp1_->predict(x0, y0, 16, 16, m1x, m1y, qpel, lists == 2 ? pred : pred1);
    if (lists == 3)
      for (int i = 0; i < 256; ++i) pred[i] = (pred[i] + pred1[i] + 1) >> 1;
  }

  // B planes: an inter candidate of prediction `kind` with the list 0 vector (m0x, m0y) and the
  // list 1 vector (m1x, m1y) (direct: the predictors); the residual is coded as in P planes. A
  // direct candidate without residual becomes a skip.
  double try_b_inter(MacroblockData& mb, ContextSet& trial, BPred kind, int m0x, int m0y, int m1x,
                     int m1y) {
    const int x0 = mb_x_ * 16, y0 = mb_y_ * 16;
    mb.type = kMbInter;
    mb.b_pred = kind;
    mb.mv_x = m0x;
    mb.mv_y = m0y;
    mb.mv_x1 = m1x;
    mb.mv_y1 = m1y;
    const int lists = b_pred_lists(kind);
    int32_t pred[256];
    b_prediction(kind, m0x, m0y, m1x, m1y, pred);
    add_cross(16, x0, y0, pred);
    // Side information: skip, is_inter and prediction flags, then the vector differences.
    double side_bits = kind == kBDirect ? 3 : (kind == kBBi ? 3 : 4);
    if (kind != kBDirect) {
      int px, py;
      if (lists & 1) {
        st_.mv_predictor_list(0, mb_x_, mb_y_, &px, &py);
        side_bits += signed_exp_golomb_bits(m0x - px) + signed_exp_golomb_bits(m0y - py);
      }
      if (lists & 2) {
        st_.mv_predictor_list(1, mb_x_, mb_y_, &px, &py);
        side_bits += signed_exp_golomb_bits(m1x - px) + signed_exp_golomb_bits(m1y - py);
      }
    }
    double cost;
    if (p_.rdo) {
      // A direct candidate without residual is a skip, which costs 2 lambda less than its
      // residual; the others add their side bits.
      const ResidualBound bound(
          this, kind == kBDirect ? bound_ + 2 * lambda_ : bound_ - lambda_ * side_bits);
      cost = code_i16_residual(mb, pred, trial, true) + lambda_ * side_bits;
    } else {
      cost = static_cast<double>(distortion_estimate(16, pred, x0, y0)) + lambda_sad_ * side_bits;
      // Only the direct candidate's residual decides its cost (a skip when it has none).
      defer_i16_residual(mb, pred, trial, true, kind == kBDirect);
    }
    mb.skip = kind == kBDirect && mb.cbp == 0 && alpha_ == 0;
    // A skip codes one flag: no prediction flags, no coded block pattern.
    if (mb.skip) cost -= p_.rdo ? lambda_ * (side_bits + 2) : lambda_sad_ * (side_bits - 1);
    return cost;
  }

  // Motion bits of vector (mx, my): the flag and nothing else for the co-located first-plane
  // vector (shared motion), else the two differences to the predictor (px, py).
  // (With several references the co-located vector is shared only with its reference.)
  double motion_bits(int mx, int my, int px, int py, int ref = 0) const {
    MotionSearchParams shared;
    set_shared(shared, ref);
    return motion_vector_bits(mx, my, px, py, shared);
  }
  void set_shared(MotionSearchParams& params, int ref = 0) const {
    const size_t i = static_cast<size_t>(mb_y_) * st_.mbs_x + mb_x_;
    params.has_shared = st_.can_share(i) && st_.colocated_ref(i) == ref;
    if (params.has_shared) {
      params.shared_mv_x = st_.colocated->mv_x[i];
      params.shared_mv_y = st_.colocated->mv_y[i];
    }
  }
  bool is_shared_vector(int mx, int my, int ref = 0) const {
    const size_t i = static_cast<size_t>(mb_y_) * st_.mbs_x + mb_x_;
    return st_.can_share(i) && st_.colocated_ref(i) == ref && mx == st_.colocated->mv_x[i] &&
           my == st_.colocated->mv_y[i];
  }

  // Inter candidate: integer motion within the search range around zero by SAD + lambda * motion
  // bits (full search with RDO, else a predictor-seeded diamond search); with sub-sample motion,
  // then the predictor, the co-located first-plane vector (shared motion) and the eight
  // half-sample (and then quarter-sample) neighbours of the best vector by SATD (SAD when
  // lossless) + lambda * motion bits (motion_search.hpp); then the residual as sixteen 4x4 blocks.
  // A forced candidate takes the co-located vector (and its reference), the predictor, or a
  // vector searched on another reference before (kGiven, format 1.6) without a search.
  double try_inter(MacroblockData& mb, ContextSet& trial, Forced forced = Forced::kNone) {
    const int x0 = mb_x_ * 16, y0 = mb_y_ * 16;
    const size_t mb_index = static_cast<size_t>(mb_y_) * st_.mbs_x + mb_x_;
    const int ref = forced == Forced::kShared ? st_.colocated_ref(mb_index)
                                              : (forced == Forced::kGiven ? given_ref_ : 0);
    int px, py;
    st_.mv_predictor(mb_x_, mb_y_, &px, &py, ref);
    const bool qpel = p_.subpel != 0;
    const int unit = qpel ? 4 : 1;  // vector units per sample
    int best_x, best_y;
    if (forced == Forced::kGiven) {
      best_x = given_.mv_x;
      best_y = given_.mv_y;
      whole_mv_x_ = given_.whole_x;
      whole_mv_y_ = given_.whole_y;
    } else if (forced == Forced::kShared) {
      // The first plane's vector as it is; its whole-sample part serves the TD candidate.
      const size_t i = static_cast<size_t>(mb_y_) * st_.mbs_x + mb_x_;
      best_x = st_.colocated->mv_x[i];
      best_y = st_.colocated->mv_y[i];
      whole_mv_x_ = best_x / unit * unit;
      whole_mv_y_ = best_y / unit * unit;
    } else if (forced == Forced::kPredictor) {
      best_x = px;
      best_y = py;
      whole_mv_x_ = whole_mv_y_ = 0;
    } else if (forced == Forced::kMerge) {  // format 1.11: merge candidate merge_k_ - 1
      best_x = merge_cand_[merge_k_ - 1][0];
      best_y = merge_cand_[merge_k_ - 1][1];
      whole_mv_x_ = whole_mv_y_ = 0;
    } else {
      const MotionSearchResult found = search_reference(0, px, py);
      best_x = found.mv_x;
      best_y = found.mv_y;
      whole_mv_x_ = found.whole_mv_x;
      whole_mv_y_ = found.whole_mv_y;
    }
    int32_t pred[256];
    mb.mv_x = mv_x_ = best_x;
    mb.mv_y = mv_y_ = best_y;
    mb.ref_idx = cur_ref_ = ref;
    mb.shared = is_shared_vector(best_x, best_y, ref);
    interp(ref).predict(x0, y0, 16, 16, best_x, best_y, qpel, pred);
    add_cross(16, x0, y0, pred);
    // Format 1.11, merge: at a candidate's vector (reference 0) the macroblock codes the
    // candidate's index (about merged + 1 bins) instead of ref_idx and a vector difference.
    const int merged = mb.shared ? -1 : merge_index(best_x, best_y, ref);
    const double mv_bits = merged > 0 ? merged + 1.0
                                      : motion_bits(best_x, best_y, px, py, ref) +
                                            (mb.shared ? 0.0 : ref_idx_bits(trial, ref));
    double cost;
    if (p_.rdo) {
      // The own search's and a given vector's costs are kept (own_) and compared later, so only
      // the shared, predicted and merge candidates stop at the bound: their cost is at least
      // the residual's less 4 lambda (a skip).
      const bool bounded =
          forced == Forced::kShared || forced == Forced::kPredictor || forced == Forced::kMerge;
      const ResidualBound bound(
          this, bounded ? bound_ + 4 * lambda_ : std::numeric_limits<double>::infinity());
      cost = code_i16_residual(mb, pred, trial, true) + lambda_ * (mv_bits - 2);
    } else {
      cost = static_cast<double>(distortion_estimate(16, pred, x0, y0)) + lambda_sad_ * mv_bits;
      defer_i16_residual(mb, pred, trial, true, true);  // a skip when it has no residual
    }
    const int idx = mb.cbp == 0 && alpha_ == 0 && !mb.shared ? skip_index(best_x, best_y, ref) : -1;
    mb.skip = mb.cbp == 0 && alpha_ == 0 && (mb.shared || idx >= 0);
    mb.merge_idx = mb.skip ? std::max(idx, 0) : std::max(merged, 0);
    // A skip codes no vector (one at a candidate's its index instead: about idx + 1 bins).
    if (mb.skip)
      cost -= (p_.rdo ? lambda_ : lambda_sad_) *
              (mv_bits + 2 - (mb.merge_idx > 0 ? mb.merge_idx + 1 : 0));
    last_cost_ = cost;
    return cost;
  }

  // Format 1.11: how a P macroblock at vector (mx, my) on reference `ref` without residual is
  // coded as a skip: 0 at the predictor, k at merge candidate k - 1 (merge), -1 not at all.
  int skip_index(int mx, int my, int ref) const {
    if (ref != 0) return -1;
    if (mx == skip_mv_x_ && my == skip_mv_y_) return 0;
    const int k = merge_index(mx, my, ref);
    return k > 0 ? k : -1;
  }
  // Format 1.11: k when (mx, my) on reference `ref` is merge candidate k - 1 (a 16x16 inter
  // macroblock there is coded as merged), else 0.
  int merge_index(int mx, int my, int ref) const {
    if (ref != 0) return 0;
    for (int k = 0; k < merge_count_; ++k)
      if (merge_cand_[k][0] == mx && merge_cand_[k][1] == my) return k + 1;
    return 0;
  }

  // ---- Format 1.7, inter partitions (docs/bitstream.md 4.11) ----
  // The partitioned candidates after the 16x16 ones: 16x8, 8x16 and 8x8, each partition's
  // vector refined from the 16x16 search result and its predictor (search_partition_motion),
  // the residual over the whole macroblock as for 16x16. With RDO (the slow preset) every type is
  // a candidate. Without (planes coded with rdo = false and partitions, which EncoderOptions'
  // fast preset does not ask for: docs/benchmarks.md, format 1.7) the type with the lowest SATD +
  // lambda * motion bits is coded as a candidate.
  void consider_partitions(Candidate& best, const ContextSet& ctx) {
    if (p_.rdo) {
      for (int t = kPart16x8; t <= kPart8x8; ++t)
        consider_candidate(&best, ctx, [&](MacroblockData& mb, ContextSet& trial) {
          return try_partitions(mb, trial, t, nullptr);
        });
      return;
    }
    int chosen = -1;
    double chosen_cost = best.cost;
    MacroblockData motion[kPartitionTypeCount];
    for (int t = kPart16x8; t <= kPart8x8; ++t) {
      int32_t pred[256];
      const double side = partition_motion(motion[t], ctx, t, nullptr, pred);
      const double cost =
          side + static_cast<double>(distortion_estimate(16, pred, mb_x_ * 16, mb_y_ * 16));
      if (cost < chosen_cost) {
        chosen = t;
        chosen_cost = cost;
      }
    }
    if (chosen < 0) return;
    consider_candidate(&best, ctx, [&](MacroblockData& mb, ContextSet& trial) {
      return try_partitions(mb, trial, chosen, &motion[chosen]);
    });
  }

  // Chooses (or, with `given`, takes given's) reference and vector of every partition of type t
  // into mb, records them in the plane's 8x8 motion (for the next partitions' predictors) and
  // writes the prediction into pred; returns lambda x the side bits (partition type over 16x16's,
  // ref_idx and vector differences) in the preset's cost units.
  double partition_motion(MacroblockData& mb, const ContextSet& ctx, int t,
                          const MacroblockData* given, int32_t* pred) {
    mb.type = kMbInter;
    mb.partition = t;
    const bool qpel = p_.subpel != 0;
    const double lambda = p_.rdo ? lambda_ : lambda_sad_;
    double bits = partition_type_bits(ctx.partition, t) - partition_type_bits(ctx.partition, 0);
    PartitionSearchParams search;
    search.subpel = p_.subpel;
    search.lossless = p_.lossless;
    search.lambda = p_.lossless ? 1.0 : kMotionLambdaScale * lambda_sad_;
    search.max_abs_mv = qpel ? 4 * kMaxMotion : kMaxMotion;
    for (int k = 0; k < partition_count(t); ++k) {
      const PartitionRect r = partition_rect(t, k);
      const int bx = mb_x_ * 16 + 8 * r.x, by = mb_y_ * 16 + 8 * r.y, w = 8 * r.w, h = 8 * r.h;
      const int ref_inc = st_.grid.ref_context(2 * mb_x_ + r.x, 2 * mb_y_ + r.y);
      const auto ref_bits = [&](int ref) {
        return p_.ref_count > 1 ? detail::ref_idx_bits(ctx.ref_idx, ref_inc, ref, p_.ref_count)
                                : 0.0;
      };
      int best_ref = 0, best_x = 0, best_y = 0;
      if (given) {
        best_ref = given->part_ref[k];
        best_x = given->part_mv_x[k];
        best_y = given->part_mv_y[k];
      } else {
        // Slow preset: every reference; fast: reference 0 and the 16x16 candidates' best one.
        double best_cost = std::numeric_limits<double>::infinity();
        int best16 = 0;
        for (int ref = 1; ref < p_.ref_count; ++ref)
          if (own_[ref].cost < own_[best16].cost) best16 = ref;
        for (int ref = 0; ref < p_.ref_count; ++ref) {
          if (!p_.rdo && ref != 0 && ref != best16) continue;
          int px, py;
          partition_mv_predictor(st_.grid, mb_x_, mb_y_, t, k, ref, &px, &py);
          const int starts[4] = {own_[ref].mv_x, own_[ref].mv_y, px, py};
          const PartitionVector v = search_partition_motion(src_, interp(ref), bx, by, w, h, px, py,
                                                            starts, search, &partition_memo_, ref);
          const double cost = v.cost + search.lambda * ref_bits(ref);
          if (cost < best_cost) {
            best_cost = cost;
            best_ref = ref;
            best_x = v.mv_x;
            best_y = v.mv_y;
          }
        }
      }
      int px, py;
      partition_mv_predictor(st_.grid, mb_x_, mb_y_, t, k, best_ref, &px, &py);
      bits += signed_exp_golomb_bits(best_x - px) + signed_exp_golomb_bits(best_y - py) +
              ref_bits(best_ref);
      mb.part_ref[k] = best_ref;
      mb.part_mv_x[k] = best_x;
      mb.part_mv_y[k] = best_y;
      st_.grid.set(mb_x_, mb_y_, r, best_ref, best_x, best_y);
    }
    mb.ref_idx = mb.part_ref[0];
    mb.mv_x = mb.part_mv_x[0];
    mb.mv_y = mb.part_mv_y[0];
    mb.shared = false;
    mb.skip = false;
    mb.td = false;
    partition_prediction(mb, pred);
    return lambda * bits;
  }

  // The prediction of a partitioned macroblock (16x16, row-major).
  void partition_prediction(const MacroblockData& mb, int32_t* pred) const {
    for (int k = 0; k < partition_count(mb.partition); ++k) {
      const PartitionRect r = partition_rect(mb.partition, k);
      const int w = 8 * r.w, h = 8 * r.h;
      int32_t block[256];
      interp(mb.part_ref[k])
          .predict(mb_x_ * 16 + 8 * r.x, mb_y_ * 16 + 8 * r.y, w, h, mb.part_mv_x[k],
                   mb.part_mv_y[k], p_.subpel != 0, block);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) pred[(8 * r.y + y) * 16 + 8 * r.x + x] = block[y * w + x];
    }
  }

  // A partitioned candidate of type t (with `given`: its motion); the residual as for 16x16.
  double try_partitions(MacroblockData& mb, ContextSet& trial, int t, const MacroblockData* given) {
    const int x0 = mb_x_ * 16, y0 = mb_y_ * 16;
    int32_t pred[256];
    const double side = partition_motion(mb, trial, t, given, pred);
    add_cross(16, x0, y0, pred);
    double cost;
    if (p_.rdo) {
      // As the 16x16 candidate: its macroblock bits (3 in code_i16_residual, 1 for inter).
      const ResidualBound bound(this, bound_ - (side - 2 * lambda_));
      cost = code_i16_residual(mb, pred, trial, true) + side - 2 * lambda_;
    } else {
      cost = static_cast<double>(distortion_estimate(16, pred, x0, y0)) + side;
      defer_i16_residual(mb, pred, trial, true, false);
    }
    return cost;
  }
  // ---- end of inter partitions ----

  // Levels of an n x n block for prediction `pred` at (x0, y0); returns true if any is nonzero.
  // Lossy planes with rdoq quantize by rate-distortion cost on the contexts `ctx` (the dead zone
  // is then the cost's); else with the intra rounding or the inter dead zone.
  bool make_levels(int n, const int32_t* pred, int x0, int y0, int32_t* levels,
                   bool inter_dead_zone, const ContextSet& ctx) const {
    int32_t residual[256];
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        residual[y * n + x] = static_cast<int32_t>(src_.at(x0 + x, y0 + y)) - pred[y * n + x];
    if (p_.lossless && p_.near_lossless > 0) {
      // Uniform quantizer of step 2 d + 1 with rounding to the nearest: |error| <= d.
      const int32_t d = p_.near_lossless, step = 2 * d + 1;
      for (int i = 0; i < n * n; ++i) {
        const int32_t a = (std::abs(residual[i]) + d) / step;
        levels[i] = residual[i] < 0 ? -a : a;
      }
    } else if (p_.lossless) {
      std::copy(residual, residual + n * n, levels);
    } else {
      int32_t coeffs[256];
      forward_transform(n, residual, coeffs);
      if (p_.rdoq && !defer_rdoq_)
        quantize_rdo(n, coeffs, p_.qp_prime, rdoq_lambda_, ctx, levels);
      else if (n == 16)
        quantize16x16(coeffs, p_.qp_prime, inter_dead_zone, levels);
      else if (inter_dead_zone)
        quantize_inter(n, coeffs, p_.qp_prime, levels);
      else
        quantize(n, coeffs, p_.qp_prime, levels);
    }
    return any_nonzero(levels, n * n);
  }

  // Reconstructs into recon_ and returns the SSD against the source.
  int64_t reconstruct(int n, const int32_t* pred, const int32_t* levels, int x0, int y0) {
    reconstruct_block(n, pred, levels, p_, recon_.samples.data(), recon_.width, x0, y0);
    int64_t ssd = 0;
    const std::vector<uint8_t>* weights = p_.distortion_weights;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const int64_t d = static_cast<int64_t>(src_.at(x0 + x, y0 + y)) - recon_.at(x0 + x, y0 + y);
        ssd +=
            weights ? (*weights)[static_cast<size_t>(y0 + y) * src_.width + x0 + x] * d * d : d * d;
      }
    return ssd;
  }

  // SATD (or SAD when lossless) of source minus prediction over an n x n block.
  int64_t distortion_estimate(int n, const int32_t* pred, int x0, int y0) const {
    const uint16_t* src = &src_.samples[static_cast<size_t>(y0) * src_.width + x0];
    return p_.lossless ? sad_block(n, src, src_.width, pred) : satd_block(n, src, src_.width, pred);
  }

  double mode_bits_estimate(int mode, int mpm) const {
    return mode == mpm ? 1.0 : (mode_count4(p_) > 9 ? 5.0 : 4.0);
  }

  // Codes the chosen block's mode and residual on the trial contexts; returns bits.
  double count_block_bits(ContextSet& trial, int n, int mode, int mpm, int mode_count,
                          const int32_t* levels, bool coded, int gx, int gy) {
    CabacBitCounter counter;
    if (mode >= 0) write_mode(counter, trial, mode, mpm, mode_count);
    if (n == 4) {
      const int left = gx > 0 ? st_.cbf_at(gx - 1, gy) : 0;
      const int top = gy > 0 ? st_.cbf_at(gx, gy - 1) : 0;
      counter.encode(trial.cbf[left + 2 * top], coded);
    }
    if (coded) write_residual(counter, trial, levels, n);
    return counter.bits();
  }

  double try_block_modes(int n, int block, int mode_count, int mpm, ContextSet& trial,
                         int8_t* chosen_mode, int32_t* chosen_levels, bool td = false) {
    const int x0 = mb_x_ * 16 + block_x(block) * 4, y0 = mb_y_ * 16 + block_y(block) * 4;
    const int gx = x0 / 4, gy = y0 / 4;
    // Intra: neighbours from the reconstruction; temporal difference: from the difference plane.
    const IntraNeighbors nb =
        td ? td_neighbors_from(
                 recon_, [&](int x, int y) { return td_window_.at(x, y); }, x0, y0, mb_x_, mb_y_,
                 block, p_.bit_depth)
           : block_neighbors(recon_, x0, y0, n, mb_x_, mb_y_, block, p_.bit_depth);
    int32_t ref_block[16];
    if (td)
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x)
          ref_block[y * 4 + x] = td_window_.at(x0 + x, y0 + y) - (1 << (p_.bit_depth - 1));
    int32_t pred[64], levels[64], best_pred[64];
    double best_cost = std::numeric_limits<double>::infinity();
    int best_mode = kIntraDc;
    // RDO on a shortlist (p_.intra_rdo_shortlist > 0): the modes of the lowest SATD-based costs
    // are coded; the others are not tried.
    const int shortlist = p_.rdo ? p_.intra_rdo_shortlist : 0;
    bool listed[kIntra4x4ModeCount];
    std::fill(listed, listed + kIntra4x4ModeCount, shortlist == 0);
    if (n == 8 && shortlist > 0 && shortlist < mode_count) {
      double costs[kIntra4x4ModeCount];
      int order[kIntra4x4ModeCount];
      for (int mode = 0; mode < mode_count; ++mode) {
        predict_intra(8, mode, nb, max_value_, pred);
        add_cross(8, x0, y0, pred);
        costs[mode] = static_cast<double>(distortion_estimate(8, pred, x0, y0)) +
                      lambda_sad_ * mode_bits_estimate(mode, mpm);
        order[mode] = mode;
      }
      std::partial_sort(order, order + shortlist, order + mode_count,
                        [&](int a, int b) { return costs[a] < costs[b]; });
      for (int k = 0; k < shortlist; ++k) listed[order[k]] = true;
    } else if (n == 8) {
      std::fill(listed, listed + kIntra4x4ModeCount, true);
    }
    if (n == 4 && (!p_.rdo || shortlist > 0)) {
      // Fast decision: every mode predicted and measured in one pass over the neighbours.
      int32_t preds[kIntra4x4ModeCount][16];
      int64_t distortion[kIntra4x4ModeCount];
      predict_intra4x4_modes(nb, max_value_, mode_count, preds);
      // The temporal-difference reference and the cross-plane term, which every mode's
      // prediction adds, are taken from the source once instead (the same differences).
      int32_t shared[16] = {};
      if (td || alpha_) {
        int32_t source[16];
        if (td) std::copy(ref_block, ref_block + 16, shared);
        add_cross(4, x0, y0, shared);
        for (int y = 0; y < 4; ++y)
          for (int x = 0; x < 4; ++x)
            source[y * 4 + x] = static_cast<int32_t>(src_.at(x0 + x, y0 + y)) - shared[y * 4 + x];
        distortions4x4_of(p_.lossless, source, preds, mode_count, distortion);
      } else {
        distortions4x4(p_.lossless, &src_.samples[static_cast<size_t>(y0) * src_.width + x0],
                       src_.width, preds, mode_count, distortion);
      }
      double costs[kIntra4x4ModeCount];
      for (int mode = 0; mode < mode_count; ++mode) {
        costs[mode] =
            static_cast<double>(distortion[mode]) + lambda_sad_ * mode_bits_estimate(mode, mpm);
        if (costs[mode] < best_cost) {
          best_cost = costs[mode];
          best_mode = mode;
        }
      }
      if (shortlist > 0) {  // the listed modes are coded below
        int order[kIntra4x4ModeCount];
        for (int mode = 0; mode < mode_count; ++mode) order[mode] = mode;
        std::partial_sort(order, order + std::min(shortlist, mode_count), order + mode_count,
                          [&](int a, int b) { return costs[a] < costs[b]; });
        for (int k = 0; k < std::min(shortlist, mode_count); ++k) listed[order[k]] = true;
        best_cost = std::numeric_limits<double>::infinity();
      } else {
        for (int i = 0; i < 16; ++i) best_pred[i] = preds[best_mode][i] + shared[i];
      }
    }
    for (int mode = 0; mode < mode_count && (n != 4 || p_.rdo); ++mode) {
      if (!listed[mode]) continue;
      predict_intra(n, mode, nb, max_value_, pred);
      if (td)
        for (int i = 0; i < 16; ++i) pred[i] += ref_block[i];
      add_cross(n, x0, y0, pred);
      double cost;
      if (p_.rdo) {
        const bool coded = make_levels(n, pred, x0, y0, levels, false, trial);
        const int64_t ssd = reconstruct(n, pred, levels, x0, y0);
        ContextSet scratch = trial;
        cost = static_cast<double>(ssd) +
               lambda_ * count_block_bits(scratch, n, mode, mpm, mode_count, levels, coded, gx, gy);
      } else {
        cost = static_cast<double>(distortion_estimate(n, pred, x0, y0)) +
               lambda_sad_ * mode_bits_estimate(mode, mpm);
      }
      if (cost < best_cost) {
        best_cost = cost;
        best_mode = mode;
        std::copy(pred, pred + n * n, best_pred);
      }
    }
    const bool coded = make_levels(n, best_pred, x0, y0, chosen_levels, false, trial);
    // (The fast decision's cost is the SATD estimate: no SSD needed.)
    int64_t ssd = 0;
    if (p_.rdo)
      ssd = reconstruct(n, best_pred, chosen_levels, x0, y0);
    else
      reconstruct_block(n, best_pred, chosen_levels, p_, recon_.samples.data(), recon_.width, x0,
                        y0);
    *chosen_mode = static_cast<int8_t>(best_mode);
    const double bits = p_.rdo ? count_block_bits(trial, n, best_mode, mpm, mode_count,
                                                  chosen_levels, coded, gx, gy)
                               : 0.0;
    for (int i = 0; i < n / 4; ++i)
      for (int j = 0; j < n / 4; ++j) {
        st_.mode_at(gx + j, gy + i) = static_cast<int8_t>(best_mode);
        st_.cbf_at(gx + j, gy + i) = coded ? 1 : 0;
      }
    return p_.rdo ? static_cast<double>(ssd) + lambda_ * bits : best_cost;
  }

  double try_i4(MacroblockData& mb, ContextSet& trial) {
    double cost = p_.rdo ? lambda_ * 2 : lambda_sad_ * 2;
    for (int b = 0; b < 16; ++b) {
      const int gx = mb_x_ * 4 + block_x(b), gy = mb_y_ * 4 + block_y(b);
      cost += try_block_modes(4, b, mode_count4(p_), most_probable_mode(st_, gx, gy, false), trial,
                              &mb.modes[b], mb.levels[b]);
      if (cost >= bound_) return cost;  // cannot win: the rest is not needed
    }
    mb.cbp = 0;
    for (int b = 0; b < 16; ++b)
      if (any_nonzero(mb.levels[b], 16)) mb.cbp |= static_cast<uint8_t>(1 << (b >> 2));
    return cost;
  }

  // Format 1.12: TD16 candidates at the own search's vector on reference `td_ref`, at the skip
  // vector and at every merge candidate (reference 0).
  void consider_td16(Candidate& best, const ContextSet& ctx, int td_ref) {
    const auto at = [&](int ref, int mx, int my) {
      cur_ref_ = ref;
      mv_x_ = mx;
      mv_y_ = my;
      consider_candidate(
          &best, ctx, [&](MacroblockData& mb, ContextSet& trial) { return try_td16(mb, trial); });
    };
    at(td_ref, own_[td_ref].mv_x, own_[td_ref].mv_y);
    if (td_ref != 0 || own_[0].mv_x != skip_mv_x_ || own_[0].mv_y != skip_mv_y_)
      at(0, skip_mv_x_, skip_mv_y_);
    for (int k = 0; k < merge_count_; ++k)
      if (td_ref != 0 || own_[0].mv_x != merge_cand_[k][0] || own_[0].mv_y != merge_cand_[k][1])
        at(0, merge_cand_[k][0], merge_cand_[k][1]);
  }

  // td_window_ over the current macroblock: reference `ref` motion-compensated at (mx, my).
  void fill_td_window_at(int ref, int mx, int my) {
    td_window_.place(mb_x_, mb_y_);
    interp(ref).predict(td_window_.x0, td_window_.y0, TdWindow::kWidth, TdWindow::kHeight, mx, my,
                        p_.subpel != 0, td_window_.mc);
  }

  // Inter with temporal-difference prediction, at the motion vector of the inter candidate.
  double try_td(MacroblockData& mb, ContextSet& trial) {
    int px, py;
    st_.mv_predictor(mb_x_, mb_y_, &px, &py, cur_ref_);
    mb.mv_x = mv_x_;
    mb.mv_y = mv_y_;
    mb.td = true;
    mb.ref_idx = cur_ref_;
    mb.shared = is_shared_vector(mv_x_, mv_y_, cur_ref_);
    const double mv_bits = motion_bits(mv_x_, mv_y_, px, py, cur_ref_) + 3 +
                           (mb.shared ? 0.0 : ref_idx_bits(trial, cur_ref_));
    double cost = p_.rdo ? lambda_ * mv_bits : lambda_sad_ * mv_bits;
    // The motion-compensated reference over the macroblock and the samples its blocks' TD
    // neighbours read (TdWindow).
    fill_td_window_at(cur_ref_, mv_x_, mv_y_);
    for (int b = 0; b < 16; ++b) {
      const int gx = mb_x_ * 4 + block_x(b), gy = mb_y_ * 4 + block_y(b);
      cost += try_block_modes(4, b, mode_count4(p_), most_probable_mode(st_, gx, gy, false), trial,
                              &mb.modes[b], mb.levels[b], true);
      if (cost >= bound_) return cost;  // cannot win: the rest is not needed
    }
    mb.cbp = 0;
    for (int b = 0; b < 16; ++b)
      if (any_nonzero(mb.levels[b], 16)) mb.cbp |= static_cast<uint8_t>(1 << (b >> 2));
    return cost;
  }

  // Format 1.12, TD16: inter at the current vector (cur_ref_, mv_x_, mv_y_) with the temporal
  // difference predicted by one I16x16 mode (format 1.13: or the quadratic one) from the
  // macroblock's neighbours (with RDO every mode, or the intra shortlist's count of lowest
  // SATD-based cost; without, the lowest), the residual coded as a plain inter macroblock's
  // (every transform size). A vector that is a merge candidate is coded merged.
  double try_td16(MacroblockData& mb, ContextSet& trial) {
    const int x0 = mb_x_ * 16, y0 = mb_y_ * 16;
    int px, py;
    st_.mv_predictor(mb_x_, mb_y_, &px, &py, cur_ref_);
    mb.type = kMbInter;
    mb.mv_x = mv_x_;
    mb.mv_y = mv_y_;
    mb.td = mb.td16 = true;
    mb.ref_idx = cur_ref_;
    mb.shared = is_shared_vector(mv_x_, mv_y_, cur_ref_);
    const int merged = mb.shared ? -1 : merge_index(mv_x_, mv_y_, cur_ref_);
    mb.merge_idx = std::max(merged, 0);
    // The td and td16 bins and the mode's two bins: about 3 bits over a plain inter MB's.
    const double side_bits =
        3 + (merged > 0 ? merged + 1.0
                        : motion_bits(mv_x_, mv_y_, px, py, cur_ref_) +
                              (mb.shared ? 0.0 : ref_idx_bits(trial, cur_ref_)));
    fill_td_window_at(cur_ref_, mv_x_, mv_y_);
    int32_t pred[256];
    // H.264's four modes, and the quadratic one where the plane may code it (format 1.13).
    const int modes =
        has_quadratic_mode(p_, mb_x_, mb_y_) ? kIntra16x16Quadratic + 1 : kIntra16x16ModeCount;
    double estimate[kIntra16x16Quadratic + 1];
    int order[kIntra16x16Quadratic + 1];
    for (int mode = 0; mode < modes; ++mode) {
      predict_td16(recon_, td_window_, mb_x_, mb_y_, mode, p_.bit_depth, pred);
      add_cross(16, x0, y0, pred);
      estimate[mode] = static_cast<double>(distortion_estimate(16, pred, x0, y0));
      order[mode] = mode;
    }
    std::sort(order, order + modes, [&](int a, int b) { return estimate[a] < estimate[b]; });
    int best_mode = order[0];
    if (p_.rdo) {
      const int shortlist =
          p_.intra_rdo_shortlist > 0 ? std::min(p_.intra_rdo_shortlist, modes) : modes;
      ModeResidual best;
      const double mode_bound = bound_ - lambda_ * (side_bits - 2);
      for (int k = 0; k < shortlist; ++k) {
        predict_td16(recon_, td_window_, mb_x_, mb_y_, order[k], p_.bit_depth, pred);
        add_cross(16, x0, y0, pred);
        ModeResidual m{mb, trial};
        const ResidualBound bound(this, std::min(mode_bound, best.cost));
        m.cost = code_i16_residual(m.mb, pred, m.contexts, true);
        if (m.cost < best.cost) {
          keep_mode_residual(m);
          best = m;
          best_mode = order[k];
        }
      }
      mb = best.mb;
      mb.i16_mode = best_mode;
      trial = best.contexts;
      restore_mode_residual();
      return best.cost + lambda_ * (side_bits - 2);
    }
    mb.i16_mode = best_mode;
    predict_td16(recon_, td_window_, mb_x_, mb_y_, best_mode, p_.bit_depth, pred);
    add_cross(16, x0, y0, pred);
    const double cost =
        static_cast<double>(distortion_estimate(16, pred, x0, y0)) + lambda_sad_ * side_bits;
    defer_i16_residual(mb, pred, trial, true, false);
    return cost;
  }

  // ---- One 16x16 mode's coded residual (I16x16 and TD16 with RDO) ----
  // A mode's macroblock data and contexts after code_i16_residual; keep_mode_residual saves the
  // reconstructed samples and coded-block flags it left in the plane, restore_mode_residual puts
  // the last kept ones back, so the best mode need not be coded a second time.
  struct ModeResidual {
    MacroblockData mb;
    ContextSet contexts;
    double cost = std::numeric_limits<double>::infinity();
  };
  void keep_mode_residual(const ModeResidual&) {
    const int x0 = mb_x_ * 16, y0 = mb_y_ * 16;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) kept_recon_[y * 16 + x] = recon_.at(x0 + x, y0 + y);
    for (int i = 0; i < 16; ++i) kept_cbf_[i] = st_.cbf_at(mb_x_ * 4 + i % 4, mb_y_ * 4 + i / 4);
  }
  void restore_mode_residual() {
    const int x0 = mb_x_ * 16, y0 = mb_y_ * 16;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) recon_.at(x0 + x, y0 + y) = kept_recon_[y * 16 + x];
    for (int i = 0; i < 16; ++i) st_.cbf_at(mb_x_ * 4 + i % 4, mb_y_ * 4 + i / 4) = kept_cbf_[i];
  }

  double try_i8(MacroblockData& mb, ContextSet& trial) {
    double cost = p_.rdo ? lambda_ * 2 : lambda_sad_ * 2;
    for (int q = 0; q < 4; ++q) {
      const int gx = mb_x_ * 4 + (q & 1) * 2, gy = mb_y_ * 4 + (q >> 1) * 2;
      cost += try_block_modes(8, q * 4, kIntra8x8ModeCount, most_probable_mode(st_, gx, gy, true),
                              trial, &mb.modes[q], mb.levels8[q]);
      if (cost >= bound_) return cost;  // cannot win: the rest is not needed
    }
    mb.cbp = 0;
    for (int q = 0; q < 4; ++q)
      if (any_nonzero(mb.levels8[q], 64)) mb.cbp |= static_cast<uint8_t>(1 << q);
    return cost;
  }

  double try_i16(MacroblockData& mb, ContextSet& trial) {
    const int x0 = mb_x_ * 16, y0 = mb_y_ * 16;
    // H.264's four modes, and the quadratic one where the plane may code it (format 1.13).
    const int modes =
        has_quadratic_mode(p_, mb_x_, mb_y_) ? kIntra16x16Quadratic + 1 : kIntra16x16ModeCount;
    int32_t pred[256];
    double best_cost = std::numeric_limits<double>::infinity();
    int best_mode = kIntraDc;
    // RDO on a shortlist (p_.intra_rdo_shortlist > 0): only the modes of the lowest SATD-based
    // costs are coded.
    bool listed[kIntra16x16Quadratic + 1] = {true, true, true, true, true};
    if (p_.rdo && p_.intra_rdo_shortlist > 0 && p_.intra_rdo_shortlist < modes) {
      double estimate[kIntra16x16Quadratic + 1];
      int order[kIntra16x16Quadratic + 1];
      for (int mode = 0; mode < modes; ++mode) {
        predict_i16(recon_, mb_x_, mb_y_, mode, p_.bit_depth, pred);
        add_cross(16, x0, y0, pred);
        estimate[mode] = static_cast<double>(distortion_estimate(16, pred, x0, y0));
        order[mode] = mode;
        listed[mode] = false;
      }
      std::sort(order, order + modes, [&](int a, int b) { return estimate[a] < estimate[b]; });
      for (int k = 0; k < p_.intra_rdo_shortlist; ++k) listed[order[k]] = true;
    }
    ModeResidual best;
    for (int mode = 0; mode < modes; ++mode) {
      if (!listed[mode]) continue;
      predict_i16(recon_, mb_x_, mb_y_, mode, p_.bit_depth, pred);
      add_cross(16, x0, y0, pred);
      double cost;
      if (p_.rdo) {
        ModeResidual m{mb, trial};
        const ResidualBound bound(this, std::min(bound_, best.cost));
        cost = m.cost = code_i16_residual(m.mb, pred, m.contexts);
        if (cost < best_cost) {
          keep_mode_residual(m);
          best = m;
        }
      } else {
        cost = static_cast<double>(distortion_estimate(16, pred, x0, y0)) + lambda_sad_ * 2;
      }
      if (cost < best_cost) {
        best_cost = cost;
        best_mode = mode;
      }
    }
    if (p_.rdo) {  // the best mode as it was coded
      mb = best.mb;
      mb.i16_mode = best_mode;
      trial = best.contexts;
      restore_mode_residual();
      return best.cost;
    }
    predict_i16(recon_, mb_x_, mb_y_, best_mode, p_.bit_depth, pred);
    add_cross(16, x0, y0, pred);
    mb.i16_mode = best_mode;
    defer_i16_residual(mb, pred, trial, false, false);
    return best_cost;
  }

  // Residual of an I16x16 or inter prediction as 16 4x4 blocks; reconstructs and returns SSD +
  // lambda R. Inter residuals (lossy, with options.inter_decimation) are quantized with the
  // inter dead zone, and sparse blocks of a few +-1 levels are dropped (x264's decimation: an
  // 8x8 quadrant scoring < 4 and a macroblock scoring < 6 are coded as zero), since their
  // coded_block_pattern / coded_block_flag / level bits cost more than the error they remove.
  // RDO candidates only (the fast preset's go through defer_i16_residual).
  double code_i16_residual(MacroblockData& mb, const int32_t* pred16, ContextSet& trial,
                           bool inter = false) {
    if (p_.max_transform > 4 && !p_.lossless) return code_residual_sizes(mb, pred16, trial, inter);
    return code_residual_4x4(mb, pred16, trial, inter);
  }

  // ---- Fast preset: a 16x16 candidate's residual coded once the candidate is kept ----
  // The fast preset's costs of plain inter, B, partitioned, TD16 and I16x16 candidates are
  // SATD-based: their residual counts only through a skip (a P or direct candidate without
  // one). So such a candidate makes its levels now only where it may be a skip
  // (`levels_now`), and its reconstruction (and otherwise its levels too) waits until
  // consider_candidate keeps it as the best so far: the same levels, samples and coded-block
  // flags as code_i16_residual gives, for the candidates that can still be chosen.
  void defer_i16_residual(MacroblockData& mb, const int32_t* pred16, const ContextSet& trial,
                          bool inter, bool levels_now) {
    std::copy(pred16, pred16 + 256, deferred_pred_);
    deferred_inter_ = inter;
    deferred_ = Deferred::kResidual;
    if (levels_now) {
      fast_levels_4x4(mb, deferred_pred_, trial, inter);
      deferred_ = Deferred::kReconstruction;
    }
  }
  void complete_deferred_residual(MacroblockData& mb, const ContextSet& trial) {
    if (deferred_ == Deferred::kResidual)
      fast_levels_4x4(mb, deferred_pred_, trial, deferred_inter_);
    int32_t preds[16][16];
    for (int b = 0; b < 16; ++b) {
      const int bx = block_x(b) * 4, by = block_y(b) * 4;
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) preds[b][y * 4 + x] = deferred_pred_[(by + y) * 16 + bx + x];
    }
    reconstruct_4x4(mb, preds);
  }
  // A 16x16 candidate's levels in the fast preset. With larger transforms, choose_transform_size
  // codes the chosen candidate's residual again with RDO quantization, so these take the fixed
  // rounding offsets (on the ICT face -4.1 % BD-rate at their speed, against -5.7 % at 0.88x the
  // speed for RDO quantization everywhere).
  void fast_levels_4x4(MacroblockData& mb, const int32_t* pred16, const ContextSet& trial,
                       bool inter) {
    int32_t preds[16][16];
    defer_rdoq_ = p_.max_transform > 4;
    make_levels_4x4(mb, pred16, trial, inter, preds);
    defer_rdoq_ = false;
  }

  // ---- Larger transforms (format 1.6, docs/bitstream.md 4.8) ----
  // The residual coded with each transform size up to max_transform (4x4, 8x8, 16x16), the
  // cheapest by SSD + lambda x CABAC bits (residual and transform_size bins, counted on copies of
  // the trial contexts) kept: its levels, cbp, transform, reconstruction and contexts. The slow
  // preset decides so for every candidate; the fast one once per MB, for the chosen candidate
  // and between 4x4 and max_transform only (choose_transform_size).
  double code_residual_sizes(MacroblockData& mb, const int32_t* pred16, ContextSet& trial,
                             bool inter) {
    const int x0 = mb_x_ * 16, y0 = mb_y_ * 16;
    double best_cost = std::numeric_limits<double>::infinity();
    int best_size = 4;
    uint8_t best_cbp = 0;
    ContextSet best_ctx;
    std::array<uint16_t, 256> best_recon;
    // Early exit (p_.transform_early_exit): the largest size first; when it leaves no level,
    // or a smaller size costs more than a larger one, the smaller sizes are not tried.
    const bool early_exit = p_.transform_early_exit && p_.rdo;
    double previous_cost = std::numeric_limits<double>::infinity();
    // (transform_early_exit compares the sizes' costs: no residual bound with it.)
    const ResidualBound no_bound_with_early_exit(
        this, early_exit ? std::numeric_limits<double>::infinity() : residual_bound_);
    bool cut = false;  // a size stopped at residual_bound_
    for (int k = 0, size = early_exit ? p_.max_transform : 4; k < 3;
         ++k, size = early_exit ? size / 2 : size * 2) {
      if (size < 4 || size > p_.max_transform) break;
      // Fast preset: 4x4 or the largest size only (8x8 as well would cost ~10 % of its speed).
      if (!p_.rdo && size != 4 && size != p_.max_transform) continue;
      ContextSet t = trial;
      // A later size is kept only if it costs less than the best so far (its transform_size
      // bins add >= 0): its residual may stop there too.
      const ResidualBound below_best(
          this, early_exit ? residual_bound_ : std::min(residual_bound_, best_cost));
      double cost = size == 4   ? code_residual_4x4(mb, pred16, t, inter)
                    : size == 8 ? code_residual_8x8(mb, pred16, t, inter)
                                : code_residual_16x16(mb, pred16, t, inter);
      if (std::isinf(cost)) {
        cut = true;
        continue;
      }
      if (mb.cbp != 0) {
        CabacBitCounter counter;
        write_transform_size(counter, t, st_, mb_x_, mb_y_, size, mb.cbp, p_.max_transform);
        cost += lambda_ * counter.bits();
      }
      if (early_exit ? cost <= best_cost : cost < best_cost) {
        best_cost = cost;
        best_size = size;
        best_cbp = mb.cbp;
        best_ctx = t;
        for (int y = 0; y < 16; ++y)
          for (int x = 0; x < 16; ++x) best_recon[y * 16 + x] = recon_.at(x0 + x, y0 + y);
      }
      if (early_exit && (mb.cbp == 0 || cost > previous_cost)) break;
      previous_cost = cost;
    }
    // Slow preset with RDO quantization: no residual at all (cbp 0), the prediction as the
    // reconstruction, when that is cheaper than every size's levels (whose cost does not count
    // what a cbp of 0 saves). ICT face: -0.28 % BD-rate in the slow preset; +0.37 % in the fast
    // one, which therefore does not try it.
    const bool try_no_residual = p_.rdoq && p_.rdo;
    const auto no_residual_cost = [&] {
      static constexpr int32_t kNoLevels[256] = {};
      return lambda_ * 3 + static_cast<double>(reconstruct(16, pred16, kNoLevels, x0, y0));
    };
    if (cut && !(best_cost < residual_bound_)) {
      // Every size reached the bound: the candidate loses, unless coding no residual undercuts
      // the bound; then the sizes are coded again in full, for the exact choice.
      if (!try_no_residual || !(no_residual_cost() < residual_bound_))
        return std::numeric_limits<double>::infinity();
      const ResidualBound unbounded(this, std::numeric_limits<double>::infinity());
      return code_residual_sizes(mb, pred16, trial, inter);
    }
    if (try_no_residual && best_cbp != 0) {
      const double cost = no_residual_cost();
      if (cost < best_cost) {
        best_cost = cost;
        best_size = 4;
        best_cbp = 0;
        best_ctx = trial;
        for (int y = 0; y < 16; ++y)
          for (int x = 0; x < 16; ++x) best_recon[y * 16 + x] = recon_.at(x0 + x, y0 + y);
      }
    }
    mb.cbp = best_cbp;
    mb.transform = best_cbp ? best_size : 4;
    trial = best_ctx;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) recon_.at(x0 + x, y0 + y) = best_recon[y * 16 + x];
    for (int i = 0; i < 16; ++i) {
      const int gx = mb_x_ * 4 + block_x(i), gy = mb_y_ * 4 + block_y(i);
      // (With cbp 0 the levels of a size tried last may remain: no block is coded.)
      st_.cbf_at(gx, gy) = best_cbp != 0 && (best_size == 4   ? any_nonzero(mb.levels[i], 16)
                                             : best_size == 8 ? ((best_cbp >> (i >> 2)) & 1) != 0
                                                              : true);
    }
    return best_cost;
  }

  // The residual as four 8x8 blocks (inter: the inter dead zone and x264's 8x8 decimation, a
  // block scoring < 4 and a macroblock scoring < 6 coded as zero).
  //
  // Every block's levels are made on the contexts from before the residual's bits (`initial`),
  // and a block is reconstructed and its bits counted once its levels are final (with
  // decimation: once the blocks so far score 6 or more, so that the macroblock is not zeroed):
  // the same levels and cost as quantizing every block first, but a candidate whose partial cost
  // reaches residual_bound_ stops there (infinity) without quantizing the rest.
  double code_residual_8x8(MacroblockData& mb, const int32_t* pred16, ContextSet& trial,
                           bool inter) {
    double cost = lambda_ * 3;
    int32_t preds[4][64];
    const bool decimate = inter && p_.inter_decimation;
    const ContextSet initial = trial;
    int total = 0, counted = 0;
    const auto count_until = [&](int end) {  // false at the bound
      for (; counted < end; ++counted)
        if (!count_block(8, preds[counted], mb.levels8[counted], mb_x_ * 16 + (counted & 1) * 8,
                         mb_y_ * 16 + (counted >> 1) * 8, trial, &cost))
          return false;
      return true;
    };
    for (int q = 0; q < 4; ++q) {
      const int bx = (q & 1) * 8, by = (q >> 1) * 8;
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) preds[q][y * 8 + x] = pred16[(by + y) * 16 + bx + x];
      make_levels(8, preds[q], mb_x_ * 16 + bx, mb_y_ * 16 + by, mb.levels8[q], decimate, initial);
      if (decimate) {
        const int score = decimation_score(mb.levels8[q], 8);
        if (score < 4)
          std::fill(mb.levels8[q], mb.levels8[q] + 64, 0);
        else
          total += score;
      }
      if ((!decimate || total >= 6) && !count_until(q + 1))
        return std::numeric_limits<double>::infinity();
    }
    if (decimate && total < 6)
      for (int q = 0; q < 4; ++q) std::fill(mb.levels8[q], mb.levels8[q] + 64, 0);
    if (!count_until(4)) return std::numeric_limits<double>::infinity();
    mb.cbp = 0;
    for (int q = 0; q < 4; ++q)
      if (any_nonzero(mb.levels8[q], 64)) mb.cbp |= static_cast<uint8_t>(1 << q);
    return cost;
  }

  // The residual as one 16x16 block (inter: the inter dead zone, and a block scoring < 6 is
  // coded as zero).
  double code_residual_16x16(MacroblockData& mb, const int32_t* pred16, ContextSet& trial,
                             bool inter) {
    const int x0 = mb_x_ * 16, y0 = mb_y_ * 16;
    const bool decimate = inter && p_.inter_decimation;
    make_levels(16, pred16, x0, y0, mb.levels16, decimate, trial);
    if (decimate && decimation_score(mb.levels16, 16) < 6) std::fill_n(mb.levels16, 256, 0);
    const bool coded = any_nonzero(mb.levels16, 256);
    mb.cbp = coded ? 15 : 0;
    const int64_t ssd = reconstruct(16, pred16, mb.levels16, x0, y0);
    // At residual_bound_ the candidate cannot be chosen: its bits need not be counted.
    if (lambda_ * 3 + static_cast<double>(ssd) >= residual_bound_)
      return std::numeric_limits<double>::infinity();
    const double bits = count_block_bits(trial, 16, -1, 0, 0, mb.levels16, coded, 0, 0);
    for (int i = 0; i < 16; ++i) st_.cbf_at(x0 / 4 + i % 4, y0 / 4 + i / 4) = coded ? 1 : 0;
    return lambda_ * 3 + static_cast<double>(ssd) + lambda_ * bits;
  }
  // ---- end of larger transforms ----

  // Reconstructs an n x n block (n = 4 or 8) of a 16x16 residual at (x0, y0), counts its bits on
  // `trial` (advancing its contexts), sets its coded-block flags and adds SSD + lambda x bits to
  // *cost; false (the bits not counted) once *cost reaches residual_bound_: every block adds a
  // cost >= 0, so the candidate cannot be chosen.
  bool count_block(int n, const int32_t* pred, const int32_t* levels, int x0, int y0,
                   ContextSet& trial, double* cost) {
    const bool coded = any_nonzero(levels, n * n);
    const int64_t ssd = reconstruct(n, pred, levels, x0, y0);
    if (*cost + static_cast<double>(ssd) >= residual_bound_) return false;  // bits >= 0
    const double bits = count_block_bits(trial, n, -1, 0, 0, levels, coded, x0 / 4, y0 / 4);
    for (int i = 0; i < (n / 4) * (n / 4); ++i)
      st_.cbf_at(x0 / 4 + i % (n / 4), y0 / 4 + i / (n / 4)) = coded ? 1 : 0;
    *cost += static_cast<double>(ssd) + lambda_ * bits;
    return *cost < residual_bound_;
  }

  // The residual as sixteen 4x4 blocks with their CABAC bits, quantized and counted by quadrant
  // as in code_residual_8x8; infinity at residual_bound_.
  double code_residual_4x4(MacroblockData& mb, const int32_t* pred16, ContextSet& trial,
                           bool inter) {
    int32_t preds[16][16];
    const bool decimate = inter && p_.inter_decimation && !p_.lossless;
    const ContextSet initial = trial;
    double cost = lambda_ * 3;
    int total = 0, counted = 0;
    const auto count_until = [&](int end) {  // false at the bound
      for (; counted < end; ++counted)
        if (!count_block(4, preds[counted], mb.levels[counted], mb_x_ * 16 + block_x(counted) * 4,
                         mb_y_ * 16 + block_y(counted) * 4, trial, &cost))
          return false;
      return true;
    };
    for (int q = 0; q < 4; ++q) {
      total += make_quadrant_levels(mb, pred16, initial, q, decimate, preds);
      if ((!decimate || total >= 6) && !count_until(4 * q + 4))
        return std::numeric_limits<double>::infinity();
    }
    finish_levels_4x4(mb, decimate, total);
    if (!count_until(16)) return std::numeric_limits<double>::infinity();
    return cost;
  }

  // The levels of a 16x16 residual as 16 4x4 blocks (with the inter dead zone and decimation
  // when `inter`), mb.cbp, and the 4x4 blocks' predictions (block order).
  void make_levels_4x4(MacroblockData& mb, const int32_t* pred16, const ContextSet& trial,
                       bool inter, int32_t (*preds)[16]) {
    const bool decimate = inter && p_.inter_decimation && !p_.lossless;
    int total = 0;
    for (int q = 0; q < 4; ++q)
      total += make_quadrant_levels(mb, pred16, trial, q, decimate, preds);
    finish_levels_4x4(mb, decimate, total);
  }

  // The predictions and levels of the four 4x4 blocks of 8x8 quadrant q (blocks 4q .. 4q + 3);
  // with decimation a quadrant scoring < 4 is zeroed. Returns its score (0 when zeroed or
  // without decimation).
  int make_quadrant_levels(MacroblockData& mb, const int32_t* pred16, const ContextSet& ctx, int q,
                           bool decimate, int32_t (*preds)[16]) {
    int score = 0;
    for (int b = 4 * q; b < 4 * q + 4; ++b) {
      const int bx = block_x(b) * 4, by = block_y(b) * 4;
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) preds[b][y * 4 + x] = pred16[(by + y) * 16 + bx + x];
      make_levels(4, preds[b], mb_x_ * 16 + bx, mb_y_ * 16 + by, mb.levels[b], decimate, ctx);
      if (decimate) score += decimation_score(mb.levels[b], 4);
    }
    if (!decimate || score >= 4) return score;
    for (int b = 4 * q; b < 4 * q + 4; ++b) std::fill(mb.levels[b], mb.levels[b] + 16, 0);
    return 0;
  }

  // With decimation a macroblock whose quadrants score < 6 in all is zeroed; then mb.cbp.
  static void finish_levels_4x4(MacroblockData& mb, bool decimate, int total) {
    if (decimate && total < 6)
      for (int b = 0; b < 16; ++b) std::fill(mb.levels[b], mb.levels[b] + 16, 0);
    mb.cbp = 0;
    for (int b = 0; b < 16; ++b)
      if (any_nonzero(mb.levels[b], 16)) mb.cbp |= static_cast<uint8_t>(1 << (b >> 2));
  }

  // Reconstructs the blocks of make_levels_4x4 into recon_ and sets their coded-block flags.
  void reconstruct_4x4(const MacroblockData& mb, const int32_t (*preds)[16]) {
    for (int b = 0; b < 16; ++b) {
      const int x0 = mb_x_ * 16 + block_x(b) * 4, y0 = mb_y_ * 16 + block_y(b) * 4;
      reconstruct(4, preds[b], mb.levels[b], x0, y0);
      st_.cbf_at(x0 / 4, y0 / 4) = any_nonzero(mb.levels[b], 16) ? 1 : 0;
    }
  }

  // x264's decimation score of an n x n block (levels in raster order): large (9) when any level
  // exceeds 1, else the sum over the nonzero levels of a weight that falls with the run of
  // zeros before it in scan order (3, 2, 2, 1, 1, 1, then 0).
  static int decimation_score(const int32_t* levels, int n) {
    static const int kWeight[6] = {3, 2, 2, 1, 1, 1};
    int score = 0, run = 0;
    bool seen = false;
    for (int i = n * n - 1; i >= 0; --i) {
      const int32_t v = levels[scan_position(n, i)];
      if (!v) {
        if (seen) ++run;
        continue;
      }
      if (std::abs(v) > 1) return 9;
      if (seen) score += run < 6 ? kWeight[run] : 0;
      seen = true;
      run = 0;
    }
    return seen ? score + (run < 6 ? kWeight[run] : 0) : 0;
  }

  const SamplePlane& src_;
  SamplePlane& recon_;
  PlaneState& st_;
  const PlaneCodingParams& p_;
  const SamplePlane* ref_;
  // Cross-plane prediction (format 1.6): the source plane's residual (null when off), the scale
  // of the candidate being coded, and the cost of its bins (added to the candidate's).
  const CrossPlaneResidual* cross_;
  int alpha_ = 0;
  double extra_cost_ = 0;
  // Interpolated references (shared with the encoder's cache, which may hand the same object
  // to other planes and frames).
  using Interpolated = std::shared_ptr<const InterpolatedReference>;
  Interpolated interp_;   // of ref_, for P planes (list 0 of B planes)
  Interpolated interp1_;  // B planes: list 1
  // Joint motion search: the other planes' interpolated references and the planes the search
  // adds up.
  std::vector<Interpolated> joint_interp_;
  std::vector<JointMotionPlane> joint_planes_;
  // Multiple reference frames (format 1.6): references 1.. and their joint-search planes.
  std::vector<Interpolated> more_interp_, more_joint_interp_;
  std::vector<std::vector<JointMotionPlane>> more_joint_planes_;
  // Per reference: the own search's vector, its whole-sample part and the candidate's cost.
  struct Searched {
    int mv_x = 0, mv_y = 0, whole_x = 0, whole_y = 0;
    double cost = std::numeric_limits<double>::infinity();
  };
  std::array<Searched, 5> own_;
  Searched given_;     // the vector a Forced::kGiven candidate takes
  int given_ref_ = 0;  // ... and its reference
  // P macroblocks, set by encode(): the predictor of reference 0 (the skip vector) and, format
  // 1.11, the merge candidates (none without merge) and the one a Forced::kMerge candidate takes
  // (1-based).
  int skip_mv_x_ = 0, skip_mv_y_ = 0;
  int merge_cand_[kMergeCandidates][2] = {};
  int merge_count_ = 0;
  // The partition searches' 8x8 distortions of the current macroblock (by reference index).
  BlockDistortionMemo partition_memo_;
  // keep_mode_residual's samples and coded-block flags of the current macroblock.
  std::array<uint16_t, 256> kept_recon_{};
  std::array<uint8_t, 16> kept_cbf_{};
  int merge_k_ = 0;
  int cur_ref_ = 0;  // reference of the inter candidate (reused by try_td)
  double last_cost_ = 0;
  const int max_value_;
  double lambda_ = 1, lambda_sad_ = 1;
  double rdoq_lambda_ = 1;  // RDO quantization's lambda
  // Fast preset with larger transforms, while coding a candidate's 16x16 residual: the fixed
  // rounding offsets, since choose_transform_size codes the chosen one's again with RDO
  // quantization.
  bool defer_rdoq_ = false;
  // Fast preset: the residual the current candidate left to be coded if it is kept
  // (defer_i16_residual): none, its reconstruction, or its levels and reconstruction; its
  // prediction and whether it is inter.
  enum class Deferred { kNone, kReconstruction, kResidual };
  Deferred deferred_ = Deferred::kNone;
  bool deferred_inter_ = false;
  int32_t deferred_pred_[256];
  int mb_x_ = 0, mb_y_ = 0;
  // Cost of the best candidate so far: a candidate whose partial cost (a sum of non-negative
  // block costs) reaches it stops early, as it cannot be chosen.
  double bound_ = std::numeric_limits<double>::infinity();
  // RDO candidates: the cost their residual (code_residual_sizes) must stay below for the
  // candidate to beat bound_, given what the candidate adds besides it (infinity: no bound). A
  // 4x4 or 8x8 residual whose partial cost reaches it stops, and its size costs infinity.
  double residual_bound_ = std::numeric_limits<double>::infinity();
  // Sets residual_bound_ for a scope.
  class ResidualBound {
   public:
    ResidualBound(MacroblockEncoder* e, double bound) : e_(e), saved_(e->residual_bound_) {
      e->residual_bound_ = bound;
    }
    ~ResidualBound() { e_->residual_bound_ = saved_; }
    ResidualBound(const ResidualBound&) = delete;
    ResidualBound& operator=(const ResidualBound&) = delete;

   private:
    MacroblockEncoder* e_;
    double saved_;
  };
  TdWindow td_window_;                   // TD candidate: the motion-compensated reference
  int mv_x_ = 0, mv_y_ = 0;              // motion vector of the inter candidate (reused by try_td)
  int whole_mv_x_ = 0, whole_mv_y_ = 0;  // the whole-sample search result (vector units)
};

}  // namespace

namespace {

PlaneEncodeResult encode_plane_impl(const SamplePlane& plane, const PlaneCodingParams& params,
                                    const SamplePlane* reference, const MotionField* shared,
                                    const JointSearchPlanes* joint, const SamplePlane* reference1,
                                    const std::vector<const SamplePlane*>* more_references,
                                    const CrossPlaneLinks* cross,
                                    ReferenceInterpolationCache* cache) {
  GVKIT_CHECK(
      plane.width > 0 && plane.height > 0 && plane.width % 16 == 0 && plane.height % 16 == 0,
      "encode_plane needs a plane of whole macroblocks");
  GVKIT_CHECK(plane.samples.size() == static_cast<size_t>(plane.width) * plane.height);
  PlaneEncodeResult result;
  result.reconstruction.width = plane.width;
  result.reconstruction.height = plane.height;
  result.reconstruction.samples.assign(plane.samples.size(), 0);
  GVKIT_CHECK(!reference || (reference->width == plane.width && reference->height == plane.height));
  PlaneState st(plane.width, plane.height);
  st.predicted = reference != nullptr;
  st.bidirectional = reference1 != nullptr;
  if (params.partitions && reference && !reference1) st.enable_partitions();  // format 1.7
  st.merge = params.merge && reference && !reference1;                        // format 1.11
  st.use_reference_motion(cross ? cross->reference_motion : nullptr);
  GVKIT_CHECK(!reference1 || (reference && !shared && reference1->width == plane.width &&
                              reference1->height == plane.height));
  if (reference && shared) {
    GVKIT_CHECK(shared->mbs_x == st.mbs_x && shared->mbs_y == st.mbs_y,
                "shared motion of another macroblock grid");
    st.colocated = shared;
  }
  const CrossPlaneResidual* cross_source = cross ? cross->source : nullptr;
  CrossPlaneResidual* residual_out = cross ? cross->residual_out : nullptr;
  if (cross_source) {
    GVKIT_CHECK(cross_source->width == plane.width && cross_source->height == plane.height,
                "cross-plane source residual of another size");
    st.cross = cross_source;
  }
  if (residual_out) residual_out->reset(plane.width, plane.height);
  ContextSet ctx{};
  ctx.adaptive_levels = params.adaptive_levels;
  if (st.partitions) init_partition_contexts(ctx.partition);  // format 1.7
  // Format 1.7: the X plane's final context states are the initial ones of Y and Z.
  if (cross && cross->contexts) {
    GVKIT_CHECK(cross->contexts->contexts.size() == kContextSetContexts,
                "cross-plane context states not recorded by a plane");
    import_context_states(*cross->contexts, ctx);
  }
  CabacEncoder encoder;
  StatsCoder coder(encoder, result.stats);
  GVKIT_CHECK(!joint || joint->sources.size() == joint->references.size());
  GVKIT_CHECK(params.ref_count >= 1 && params.ref_count <= 5);
  if (params.ref_count > 1) {
    GVKIT_CHECK(reference && !reference1 && more_references &&
                    more_references->size() + 1 >= static_cast<size_t>(params.ref_count),
                "encode_plane: fewer references than ref_count");
    for (int k = 0; k + 1 < params.ref_count; ++k)
      GVKIT_CHECK((*more_references)[k]->width == plane.width &&
                  (*more_references)[k]->height == plane.height);
    GVKIT_CHECK(!joint || joint->references.empty() ||
                joint->more_references.size() + 1 >= static_cast<size_t>(params.ref_count));
  }
  MacroblockEncoder mb_encoder(plane, result.reconstruction, st, params, reference,
                               reference && !reference1 ? joint : nullptr, reference1,
                               more_references, cross_source, cache);
  for (int mb_y = 0; mb_y < st.mbs_y; ++mb_y)
    for (int mb_x = 0; mb_x < st.mbs_x; ++mb_x) {
      const MacroblockData mb =
          reference1 ? mb_encoder.encode_b(mb_x, mb_y, ctx) : mb_encoder.encode(mb_x, mb_y, ctx);
      write_macroblock(coder, ctx, st, mb_x, mb_y, mb, params);
      if (residual_out)
        record_macroblock_residual(*residual_out, mb_x, mb_y, mb, params, cross_source);
      if (st.codes_cross_scale(mb_x, mb_y) && !(mb.type == kMbInter && mb.skip))
        ++result.stats.cross_scale_mbs[cross_scale_index(mb.cross_scale)];
      if (has_transform_size(mb, params) && mb.transform > 4)
        ++(mb.transform == 16 ? result.stats.transform16_mbs : result.stats.transform8_mbs);
      if (mb.type != kMbInter) {
        ++result.stats.intra_mbs;
        if (mb.type == kMbI16x16 && mb.i16_mode == kIntra16x16Quadratic)
          ++result.stats.quadratic_mbs;  // format 1.13
      } else if (mb.skip) {
        ++result.stats.skip_mbs;
        if (mb.merge_idx > 0) ++result.stats.merge_skip_mbs;  // format 1.11
      } else if (mb.td) {
        ++result.stats.td_mbs;
        if (mb.td16) ++result.stats.td16_mbs;  // format 1.12
      } else
        ++result.stats.inter_mbs;
      if (mb.type == kMbInter && !mb.skip && mb.merge_idx > 0) ++result.stats.merged_mbs;  // 1.11
      if (st.partitions && mb.type == kMbInter && !mb.skip && !mb.shared && !mb.td)
        ++result.stats.partition_mbs[mb.partition];  // format 1.7
    }
  deblock_coded_plane(result.reconstruction, st, params);  // format 1.8
  if (params.end_of_plane_bin) {
    encoder.encode_terminate(1);
    result.bytes = encoder.finish();
  } else {
    result.bytes = encoder.finish_unterminated();  // format 1.10
  }
  if (reference && !reference1) st.export_motion(result.motion);
  if (cross && cross->contexts_out) export_context_states(ctx, *cross->contexts_out);  // 1.7
  return result;
}

}  // namespace

PlaneEncodeResult encode_plane(const SamplePlane& plane, const PlaneCodingParams& params,
                               const SamplePlane* reference, const MotionField* shared,
                               const JointSearchPlanes* joint,
                               const std::vector<const SamplePlane*>* more_references,
                               const CrossPlaneLinks* cross, ReferenceInterpolationCache* cache) {
  return encode_plane_impl(plane, params, reference, shared, joint, nullptr, more_references, cross,
                           cache);
}

PlaneEncodeResult encode_b_plane(const SamplePlane& plane, const PlaneCodingParams& params,
                                 const SamplePlane& reference0, const SamplePlane& reference1,
                                 const CrossPlaneLinks* cross, ReferenceInterpolationCache* cache) {
  PlaneCodingParams p = params;
  p.td_prediction = false;
  p.ref_count = 1;
  p.partitions = false;  // format 1.7: P planes only
  return encode_plane_impl(plane, p, &reference0, nullptr, nullptr, &reference1, nullptr, cross,
                           cache);
}

}  // namespace gvkit::codec
