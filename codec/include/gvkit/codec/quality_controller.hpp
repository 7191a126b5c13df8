#pragma once
// Constant-quality rate control (encoder only; the stream carries each frame's QP): each frame
// gets the coarsest QP whose reconstruction meets a geometry target, options.target_psnr_db (dB,
// peak = the sequence's box diagonal) or options.target_rms_mm (RMS point error, mm), measured
// with geometry_error() over the domain pixels of exactly what the decoder will output. With
// options.intra_target_offset_db > 0, I frames aim that much higher (a finer reference for the P
// frames that follow, as p_qp_offset does at constant QP).
//
// The search, per frame type (I or P), starts at that type's QP of the previous frame (the first
// I frame at options.qp, the first P frame at the I frame's QP plus the intra offset in dB as
// QP steps), and re-encodes the whole frame at each QP it tries:
// - the frame meets the target there: try up to kMaxCoarser = 2 coarser QPs, one at a time, while
//   they meet it (the QP rises by at most 2 per frame; a slowly easing sequence climbs over a few
//   frames): 2 or 3 encodes; the first frame of each type has no such bracket and searches
//   coarser like the next case searches finer;
// - it misses: step finer by the QP change that the error model RMS ~ 2^(QP / 6) predicts (at
//   least 1), doubling the step while the frame still misses, then bisect between the finest miss
//   and the coarsest meet: 1 + d + b encodes, d doubling steps and b = ceil(log2(gap)) bisection
//   steps; the typical case is 3 or 4. The worst case, a jump across the whole QP range (99
//   steps at 16 bits: steps 1, 2, ..., 64, then 6 bisection steps), is 1 + 7 + 6 = 14 encodes;
//   the first frame's coarser search has the same bound.
// So constant quality costs 2-4 encodes per frame, i.e. 2-4x the encode time of constant QP.
// A frame that misses the target even at the finest QP keeps that QP and is counted in
// frames_missed() (create() rejects targets below the error of the sample quantization itself).

#include <cstdint>
#include <memory>
#include <vector>

#include "gvkit/codec/encoder_options.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/plane_coding.hpp"
#include "gvkit/codec/sequence_info.hpp"
#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::codec {

class QualityController {
 public:
  static constexpr int kMaxCoarser = 2;  // QP steps above the previous frame's QP tried per frame

  // options.constant_quality() (contract). Fails when the target asks for less error than the
  // sequence's B-bit samples carry (RMS below one quantization step), naming the option.
  static Result<std::unique_ptr<QualityController>> create(const EncoderOptions& options,
                                                           const SequenceInfo& info);

  // Encodes frame `number` (intra when reference is null, P from it, or B from reference and
  // reference1 when both are given) at the coarsest QP that meets the target within the search
  // above; each frame type (I, P, B) keeps its own previous QP. *qp_used gets the QP. Fails as
  // encode_frame fails; `cache` as for encode_frame.
  Result<EncodedFrame> encode(const GeometryImage& frame, const SequenceInfo& info,
                              const EncoderOptions& options, uint32_t number,
                              const std::vector<SamplePlane>* reference,
                              const std::vector<SamplePlane>* reference1 = nullptr,
                              int* qp_used = nullptr,
                              const std::vector<const std::vector<SamplePlane>*>* older = nullptr,
                              ReferenceInterpolationCache* cache = nullptr);

  // Whether a frame's error meets the target (of an I frame when intra).
  bool meets(const GeometryError& error, bool intra) const;
  // The RMS error (mm) a frame must not exceed.
  double target_rms(bool intra) const;

  // Encodes spent on each frame so far, indexed by frame number (1 = no re-encode; 0 for a
  // frame not coded yet).
  const std::vector<int>& frame_encodes() const { return frame_encodes_; }
  int64_t total_encodes() const { return total_encodes_; }
  int64_t frames_missed() const { return frames_missed_; }

 private:
  QualityController() = default;
  double target_psnr_db_ = 0, target_rms_mm_ = 0, peak_mm_ = 0, intra_offset_db_ = 0;
  int qp_min_ = 0;
  int last_qp_[3] = {0, 0, 0};  // per type: 0 intra, 1 predicted, 2 bidirectional
  bool have_last_[3] = {false, false, false};
  std::vector<int> frame_encodes_;
  int64_t total_encodes_ = 0, frames_missed_ = 0;
};

}  // namespace gvkit::codec
