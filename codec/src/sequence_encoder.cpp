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

SequenceEncoder::~SequenceEncoder() {
  if (b_frames_.valid()) b_frames_.wait();
}

bool SequenceEncoder::frame_threads() const {
  return options_.threads > 1 && !rate_ && !quality_ && options_.b_frames() > 0;
}

Result<SequenceFrame> SequenceEncoder::code(const GeometryImage& frame, uint32_t number, bool intra,
                                            const Planes* reference, const Planes* reference1,
                                            const EncoderOptions& options, Planes* planes_out) {
  SequenceFrame out;
  out.number = number;
  out.type = intra
                 ? format::FrameType::kIntra
                 : (reference1 ? format::FrameType::kBidirectional : format::FrameType::kPredicted);
  GVKIT_CHECK(intra == options.is_intra(number));
  GVKIT_CHECK(intra || reference);
  std::vector<const Planes*> older;
  if (!reference1)
    for (const auto& a : older_anchors_) older.push_back(a.get());
  static const Planes kNone;
  GVKIT_ASSIGN_OR_RETURN(
      EncodedFrame encoded,
      encode_sequence_frame(frame, info_, options, number, reference ? *reference : kNone,
                            rate_.get(), &out.qp, reference1, quality_.get(), &older,
                            &interpolation_));
  out.packet = std::move(encoded.packet);
  out.reconstruction = std::move(encoded.reconstruction);
  out.stats.intra = intra;
  out.stats.bidirectional = reference1 != nullptr;
  out.stats.planes = std::move(encoded.plane_stats);
  if (planes_out) *planes_out = std::move(encoded.planes);
  return out;
}

Result<std::vector<SequenceFrame>> SequenceEncoder::collect_b_frames() {
  if (!b_frames_.valid()) return std::vector<SequenceFrame>{};
  return b_frames_.get();
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
  const bool intra = options_.is_intra(number);
  auto anchor = std::make_shared<Planes>();
  Result<SequenceFrame> coded =
      code(frame, number, intra, intra ? nullptr : anchor_.get(), nullptr, options_, anchor.get());
  interpolation_.next_frame();
  // The background B frames (before this anchor in decode order) leave first.
  GVKIT_ASSIGN_OR_RETURN(done, collect_b_frames());
  if (!coded.is_ok()) return coded.status();
  done.push_back(std::move(coded).value());
  // The B frames between the previous anchor (list 0) and this one (list 1).
  std::shared_ptr<const Planes> list0 = anchor_, list1 = anchor;
  if (!pending_.empty() && frame_threads()) {
    EncoderOptions b_options = options_;
    b_options.threads = 1;  // the second thread; this one goes on with the next anchor
    b_frames_ = std::async(std::launch::async,
                           [this, list0, list1, b_options,
                            pending = std::move(pending_)]() -> Result<std::vector<SequenceFrame>> {
                             std::vector<SequenceFrame> frames;
                             for (const Pending& p : pending) {
                               GVKIT_ASSIGN_OR_RETURN(SequenceFrame b,
                                                      code(p.frame, p.number, false, list0.get(),
                                                           list1.get(), b_options, nullptr));
                               frames.push_back(std::move(b));
                             }
                             return frames;
                           });
  } else {
    for (const Pending& p : pending_) {
      GVKIT_ASSIGN_OR_RETURN(SequenceFrame b, code(p.frame, p.number, false, list0.get(),
                                                   list1.get(), options_, nullptr));
      interpolation_.next_frame();
      done.push_back(std::move(b));
    }
  }
  pending_.clear();
  set_anchor(std::move(anchor), number);
  return done;
}

void SequenceEncoder::set_anchor(std::shared_ptr<const Planes> planes, uint32_t number) {
  // The reference list never reaches past the last I frame.
  if (options_.is_intra(number)) {
    older_anchors_.clear();
  } else if (options_.reference_frames() > 1 && anchor_) {
    older_anchors_.push_front(std::move(anchor_));
    while (older_anchors_.size() > static_cast<size_t>(options_.reference_frames() - 1))
      older_anchors_.pop_back();
  }
  anchor_ = std::move(planes);
}

Result<std::vector<SequenceFrame>> SequenceEncoder::flush() {
  // The frames after the last anchor become P frames. The first of them needs only that anchor,
  // so it is coded while the background B frames (before it in decode order) are still being
  // coded; they are collected after it and leave first.
  std::vector<SequenceFrame> done;
  bool collected = false;
  for (const Pending& p : pending_) {
    auto planes = std::make_shared<Planes>();
    Result<SequenceFrame> coded =
        code(p.frame, p.number, false, anchor_.get(), nullptr, options_, planes.get());
    interpolation_.next_frame();
    if (!collected) {
      GVKIT_ASSIGN_OR_RETURN(done, collect_b_frames());
      collected = true;
    }
    if (!coded.is_ok()) return coded.status();
    done.push_back(std::move(coded).value());
    set_anchor(std::move(planes), p.number);
  }
  pending_.clear();
  if (!collected) return collect_b_frames();
  return done;
}

}  // namespace gvkit::codec
