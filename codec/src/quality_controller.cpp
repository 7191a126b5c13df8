#include "gvkit/codec/quality_controller.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

namespace gvkit::codec {
namespace {

// A QP step from the error model, clamped to [1, max_steps] in double before the conversion (a
// non-finite error would make the conversion undefined).
int qp_steps(double model_steps, int max_steps) {
  if (!std::isfinite(model_steps)) return max_steps;
  return static_cast<int>(std::clamp(model_steps, 1.0, static_cast<double>(max_steps)));
}

}  // namespace

Result<std::unique_ptr<QualityController>> QualityController::create(const EncoderOptions& options,
                                                                     const SequenceInfo& info) {
  GVKIT_CHECK(options.constant_quality());
  std::unique_ptr<QualityController> q(new QualityController());
  q->peak_mm_ = info.box_diagonal_mm();
  q->target_psnr_db_ = options.target_psnr_db;
  // A PSNR target is an RMS target: PSNR = 20 log10(peak / RMS).
  q->target_rms_mm_ = options.target_psnr_db > 0
                          ? q->peak_mm_ * std::pow(10.0, -options.target_psnr_db / 20.0)
                          : options.target_rms_mm;
  q->intra_offset_db_ = options.intra_target_offset_db;
  q->qp_min_ = -6 * (options.bit_depth - 8);
  const double step_mm = info.step_mm();
  if (q->target_rms(true) < step_mm) {
    const std::string what = options.target_psnr_db > 0
                                 ? "target PSNR " + std::to_string(options.target_psnr_db) +
                                       " dB (RMS " + std::to_string(q->target_rms_mm_) + " mm)"
                                 : "target RMS " + std::to_string(options.target_rms_mm) + " mm";
    return invalid_argument(what + " is below one quantization step (" + std::to_string(step_mm) +
                            " mm) of " + std::to_string(options.bit_depth) +
                            "-bit samples; lower the target or raise the bit depth");
  }
  return q;
}

double QualityController::target_rms(bool intra) const {
  return intra ? target_rms_mm_ * std::pow(10.0, -intra_offset_db_ / 20.0) : target_rms_mm_;
}

bool QualityController::meets(const GeometryError& error, bool intra) const {
  // Compare in the target's own terms, so that a frame reported at the target PSNR meets it.
  if (target_psnr_db_ > 0)
    return error.psnr_db(peak_mm_) >= target_psnr_db_ + (intra ? intra_offset_db_ : 0.0);
  return error.rms_mm <= target_rms(intra);
}

Result<EncodedFrame> QualityController::encode(
    const GeometryImage& frame, const SequenceInfo& info, const EncoderOptions& options,
    uint32_t number, const std::vector<SamplePlane>* reference,
    const std::vector<SamplePlane>* reference1, int* qp_used,
    const std::vector<const std::vector<SamplePlane>*>* older, ReferenceInterpolationCache* cache) {
  const bool intra = reference == nullptr;
  GVKIT_CHECK(!intra || !reference1, "a B frame needs both references");
  const int type = intra ? 0 : (reference1 ? 2 : 1);
  // The first P frame starts from the I frame's QP, less what the I frame's higher target took
  // (1 QP is about 1 dB); the first B frame from the P frames' QP.
  const int offset_qp = static_cast<int>(std::lround(intra_offset_db_));
  int start = have_last_[type]             ? last_qp_[type]
              : type == 2 && have_last_[1] ? last_qp_[1]
              : have_last_[0]              ? last_qp_[0] + offset_qp
                                           : options.qp;
  start = std::clamp(start, qp_min_, 51);
  EncoderOptions o = options;
  o.p_qp_offset = 0;  // the search sets each frame's QP itself
  o.b_qp_offset = 0;
  int encodes = 0;
  std::optional<EncodedFrame> best, finest_miss;  // the coarsest QP that meets; the finest miss
  int best_qp = 0, finest_miss_qp = 52;
  double last_rms_mm = 0;
  auto try_qp = [&](int qp) -> Result<bool> {
    o.qp = qp;
    ++encodes;
    GVKIT_ASSIGN_OR_RETURN(EncodedFrame encoded, encode_frame(frame, info, o, number, reference,
                                                              reference1, older, cache));
    const GeometryError error = geometry_error(frame, encoded.reconstruction);
    last_rms_mm = error.rms_mm;
    if (meets(error, intra)) {
      if (!best || qp > best_qp) {
        best = std::move(encoded);
        best_qp = qp;
      }
      return true;
    }
    if (qp < finest_miss_qp) {
      finest_miss = std::move(encoded);
      finest_miss_qp = qp;
    }
    return false;
  };

  GVKIT_ASSIGN_OR_RETURN(const bool start_meets, try_qp(start));
  if (start_meets && have_last_[type]) {
    for (int qp = start + 1; qp <= std::min(51, start + kMaxCoarser); ++qp) {
      GVKIT_ASSIGN_OR_RETURN(const bool coarser_meets, try_qp(qp));
      if (!coarser_meets) break;
    }
  } else if (start_meets) {
    // The first frame of its type: no previous QP to stay near, so coarser without a bracket, by
    // the model's step (doubled while the frame meets), then bisect (pass, miss).
    const double ratio = target_rms(intra) / std::max(last_rms_mm, 1e-12);
    int step = qp_steps(std::floor(6.0 * std::log2(ratio)), 51 - qp_min_);
    int pass = start;
    std::optional<int> miss;
    while (pass < 51) {
      const int qp = std::min(51, pass + step);
      GVKIT_ASSIGN_OR_RETURN(const bool coarser_meets, try_qp(qp));
      if (!coarser_meets) {
        miss = qp;
        break;
      }
      pass = qp;
      step *= 2;
    }
    while (miss && pass + 1 < *miss) {
      const int mid = pass + (*miss - pass) / 2;
      GVKIT_ASSIGN_OR_RETURN(const bool mid_meets, try_qp(mid));
      if (mid_meets)
        pass = mid;
      else
        miss = mid;
    }
  } else {
    // Finer: the step the model RMS ~ 2^(QP / 6) predicts, doubled while the frame still misses.
    int step = qp_steps(std::ceil(6.0 * std::log2(last_rms_mm / target_rms(intra))), 51 - qp_min_);
    int miss = start;
    std::optional<int> pass;
    while (miss > qp_min_) {
      const int qp = std::max(qp_min_, miss - step);
      GVKIT_ASSIGN_OR_RETURN(const bool finer_meets, try_qp(qp));
      if (finer_meets) {
        pass = qp;
        break;
      }
      miss = qp;
      step *= 2;
    }
    // Bisect (pass, miss) for the coarsest QP that meets.
    while (pass && *pass + 1 < miss) {
      const int mid = *pass + (miss - *pass) / 2;
      GVKIT_ASSIGN_OR_RETURN(const bool mid_meets, try_qp(mid));
      if (mid_meets)
        pass = mid;
      else
        miss = mid;
    }
  }

  if (frame_encodes_.size() <= number) frame_encodes_.resize(number + 1, 0);
  frame_encodes_[number] = encodes;
  total_encodes_ += encodes;
  int qp = best_qp;
  EncodedFrame out;
  if (best) {
    out = std::move(*best);
  } else {  // missed even at the finest QP: keep it
    ++frames_missed_;
    qp = finest_miss_qp;
    out = std::move(*finest_miss);
  }
  last_qp_[type] = qp;
  have_last_[type] = true;
  if (qp_used) *qp_used = qp;
  return out;
}

}  // namespace gvkit::codec
