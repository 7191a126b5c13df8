#include "gvkit/codec/sequence_encoder.hpp"

#include <chrono>
#include <utility>

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include "gvkit/codec/gvid_writer.hpp"

namespace gvkit::codec {
namespace {

// The calling thread's scheduling priority lowered (Linux: nice + 10 for this thread only), so
// that the background B frames take the cores the anchors leave idle instead of sharing them
// with the anchors, whose chain is the encode's critical path. Elsewhere nothing changes.
void lower_thread_priority() {
#if defined(__linux__)
  const auto tid = static_cast<id_t>(syscall(SYS_gettid));
  const int now = getpriority(PRIO_PROCESS, tid);
  setpriority(PRIO_PROCESS, tid, now + 10);  // best effort: a failure leaves it as it was
#endif
}

}  // namespace

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
  for (Outgoing& o : outgoing_)
    if (o.batch.valid()) o.batch.wait();
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

Status SequenceEncoder::release(std::vector<SequenceFrame>* done, int batches_left) {
  Status failed = Status::ok();
  while (!outgoing_.empty()) {
    Outgoing& o = outgoing_.front();
    if (o.batch.valid()) {
      if (batches_ <= batches_left &&
          o.batch.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
        break;
      Result<std::vector<SequenceFrame>> frames = o.batch.get();
      --batches_;
      if (!frames.is_ok()) {
        if (failed.is_ok()) failed = frames.status();
      } else {
        o.frames = std::move(frames).value();
      }
    }
    for (SequenceFrame& f : o.frames) done->push_back(std::move(f));
    outgoing_.pop_front();
  }
  return failed;
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
  if (!coded.is_ok()) {
    GVKIT_RETURN_IF_ERROR(release(&done, 0));  // the background batches end first
    return coded.status();
  }
  // The B frames between the previous anchor (list 0) and this one (list 1).
  std::shared_ptr<const Planes> list0 = anchor_, list1 = anchor;
  if (frame_threads()) {
    // This anchor leaves after the batches before it, and its B frames after it.
    outgoing_.push_back({{std::move(coded).value()}, {}});
    if (!pending_.empty()) {
      // At most one batch from before runs on beside the new one.
      GVKIT_RETURN_IF_ERROR(release(&done, 1));
      EncoderOptions b_options = options_;
      b_options.threads = 1;  // a thread of its own; this one goes on with the next anchor
      outgoing_.push_back(
          {{},
           std::async(std::launch::async,
                      [this, list0, list1, b_options,
                       pending = std::move(pending_)]() -> Result<std::vector<SequenceFrame>> {
                        lower_thread_priority();
                        std::vector<SequenceFrame> frames;
                        for (const Pending& p : pending) {
                          GVKIT_ASSIGN_OR_RETURN(SequenceFrame b,
                                                 code(p.frame, p.number, false, list0.get(),
                                                      list1.get(), b_options, nullptr));
                          frames.push_back(std::move(b));
                        }
                        return frames;
                      })});
      ++batches_;
    }
    GVKIT_RETURN_IF_ERROR(release(&done, batches_));
  } else {
    done.push_back(std::move(coded).value());
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
  // The frames after the last anchor become P frames. They need only the anchors, so they are
  // coded while the background B frames (before them in decode order) still are, and leave
  // after them.
  std::vector<SequenceFrame> done;
  for (const Pending& p : pending_) {
    auto planes = std::make_shared<Planes>();
    Result<SequenceFrame> coded =
        code(p.frame, p.number, false, anchor_.get(), nullptr, options_, planes.get());
    interpolation_.next_frame();
    if (!coded.is_ok()) {
      GVKIT_RETURN_IF_ERROR(release(&done, 0));
      return coded.status();
    }
    outgoing_.push_back({{std::move(coded).value()}, {}});
    set_anchor(std::move(planes), p.number);
  }
  pending_.clear();
  GVKIT_RETURN_IF_ERROR(release(&done, 0));
  return done;
}

}  // namespace gvkit::codec
