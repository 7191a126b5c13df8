#include "gvkit/codec/sequence_encoder.hpp"

#include <utility>

#include "gvkit/codec/gvid_writer.hpp"

namespace gvkit::codec {

SequenceEncoder::SequenceEncoder(const SequenceInfo& info, const EncoderOptions& options)
    : info_(info), options_(options) {
  if (options.bitrate_kbps > 0) rate_ = std::make_unique<RateController>(options, info.fps);
}

Result<std::unique_ptr<SequenceEncoder>> SequenceEncoder::create(const SequenceInfo& info,
                                                                 const EncoderOptions& options) {
  std::unique_ptr<SequenceEncoder> e(new SequenceEncoder(info, options));
  if (options.constant_quality()) {
    GVKIT_ASSIGN_OR_RETURN(e->quality_, QualityController::create(options, info));
  }
  return e;
}

Result<SequenceFrame> SequenceEncoder::code(const GeometryImage& frame, uint32_t number, bool intra,
                                            const std::vector<SamplePlane>* reference1,
                                            std::vector<SamplePlane>* planes_out) {
  SequenceFrame out;
  out.number = number;
  out.type = intra
                 ? format::FrameType::kIntra
                 : (reference1 ? format::FrameType::kBidirectional : format::FrameType::kPredicted);
  GVKIT_CHECK(intra == options_.is_intra(number));
  std::vector<const std::vector<SamplePlane>*> older;
  for (const auto& a : older_anchors_) older.push_back(&a);
  GVKIT_ASSIGN_OR_RETURN(
      EncodedFrame encoded,
      encode_sequence_frame(frame, info_, options_, number, anchor_, rate_.get(), &out.qp,
                            reference1, quality_.get(), &older, &interpolation_));
  interpolation_.next_frame();
  out.packet = std::move(encoded.packet);
  out.reconstruction = std::move(encoded.reconstruction);
  out.stats.intra = intra;
  out.stats.bidirectional = reference1 != nullptr;
  out.stats.planes = std::move(encoded.plane_stats);
  if (planes_out) *planes_out = std::move(encoded.planes);
  return out;
}

Result<std::vector<SequenceFrame>> SequenceEncoder::push(const GeometryImage& frame) {
  const uint32_t number = next_number_++;
  std::vector<SequenceFrame> done;
  if (!options_.is_anchor(number)) {
    // Validated now, so that a bad frame fails at its own push.
    if (frame.xyz_mm.rows != info_.height || frame.xyz_mm.cols != info_.width)
      return invalid_argument("frame " + std::to_string(number) +
                              ": size differs from the sequence's");
    Pending p{number, frame};
    p.frame.xyz_mm = frame.xyz_mm.clone();
    if (!frame.texture.empty()) p.frame.texture = frame.texture.clone();
    pending_.push_back(std::move(p));
    return done;
  }
  std::vector<SamplePlane> anchor;
  GVKIT_ASSIGN_OR_RETURN(SequenceFrame coded,
                         code(frame, number, options_.is_intra(number), nullptr, &anchor));
  done.push_back(std::move(coded));
  // The B frames between the previous anchor (list 0) and this one (list 1).
  for (const Pending& p : pending_) {
    GVKIT_ASSIGN_OR_RETURN(SequenceFrame b, code(p.frame, p.number, false, &anchor, nullptr));
    done.push_back(std::move(b));
  }
  pending_.clear();
  set_anchor(std::move(anchor), number);
  return done;
}

void SequenceEncoder::set_anchor(std::vector<SamplePlane> planes, uint32_t number) {
  // The reference list never reaches past the last I frame.
  if (options_.is_intra(number)) {
    older_anchors_.clear();
  } else if (options_.reference_frames() > 1 && !anchor_.empty()) {
    older_anchors_.push_front(std::move(anchor_));
    while (older_anchors_.size() > static_cast<size_t>(options_.reference_frames() - 1))
      older_anchors_.pop_back();
  }
  anchor_ = std::move(planes);
}

Result<std::vector<SequenceFrame>> SequenceEncoder::flush() {
  std::vector<SequenceFrame> done;
  for (const Pending& p : pending_) {
    std::vector<SamplePlane> planes;
    GVKIT_ASSIGN_OR_RETURN(SequenceFrame coded, code(p.frame, p.number, false, nullptr, &planes));
    done.push_back(std::move(coded));
    set_anchor(std::move(planes), p.number);
  }
  pending_.clear();
  return done;
}

}  // namespace gvkit::codec
