#pragma once
// SequenceEncoder: the frame order of a .gvid encode. Frames come in display order; anchors (I
// and P frames, EncoderOptions::is_anchor) are coded when they arrive, and the B-frame
// candidates between two anchors wait for the second one and are then coded as B frames
// predicted from both (format 1.5). Coded frames leave in decode order: an anchor, then the B
// frames before it. Candidates still waiting at the end (no anchor follows) are coded as P
// frames by flush(). With bframes = 0 every frame is coded when it arrives, as in format 1.4.
//
// Frame-level threads (options.threads > 1, constant QP, B frames on): the B frames between two
// anchors depend on those anchors only, so they are coded on a thread of their own (a batch),
// at a lower scheduling priority, while this one codes the next anchors: the anchors' chain is
// the encode's critical path, and the B frames fill the cores it leaves idle. A batch may run on
// while the next two anchors are coded (at most two batches at once); frames leave once every
// frame before them in decode order is done. The stream is the same byte for byte as with one
// thread; only the frames leave one or two pushes later.

#include <cstdint>
#include <deque>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include "gvkit/codec/coding_stats.hpp"
#include "gvkit/codec/encoder_options.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/interpolation_cache.hpp"
#include "gvkit/codec/quality_controller.hpp"
#include "gvkit/codec/rate_controller.hpp"
#include "gvkit/codec/sequence_info.hpp"
#include "gvkit/core/geometry_image.hpp"

namespace gvkit::codec {

// One coded frame.
struct SequenceFrame {
  uint32_t number = 0;  // display index
  format::FrameType type = format::FrameType::kIntra;
  std::string packet;            // header + payload
  GeometryImage reconstruction;  // exactly what a decoder will output
  int qp = 0;                    // frame QP (0 for bypass frames)
  FrameCodingStats stats;
};

class SequenceEncoder {
 public:
  // options and info must pass their check() and agree on the bit depth (contract; GvidWriter
  // and encode_gvid check them). Fails when the constant-quality target cannot be met at the
  // sequence's bit depth (QualityController::create), naming the option.
  static Result<std::unique_ptr<SequenceEncoder>> create(const SequenceInfo& info,
                                                         const EncoderOptions& options);
  ~SequenceEncoder();  // waits for the background B frames

  // Takes the next frame in display order; returns the frames this completes, in decode order
  // (none while it waits as a B-frame candidate; with frame threads, an anchor and its B frames
  // leave with a later push or flush()). Fails naming the frame on bad input.
  Result<std::vector<SequenceFrame>> push(const GeometryImage& frame);
  // Codes the frames still waiting, as P frames, in display order; returns every frame not
  // returned yet, in decode order.
  Result<std::vector<SequenceFrame>> flush();

  // Frames pushed so far.
  int64_t frames_pushed() const { return next_number_; }
  // The rate controller when options.bitrate_kbps > 0, else null.
  const RateController* rate_controller() const { return rate_.get(); }
  // The constant-quality search when options.constant_quality(), else null.
  const QualityController* quality_controller() const { return quality_.get(); }

 private:
  using Planes = std::vector<SamplePlane>;
  SequenceEncoder(const SequenceInfo& info, const EncoderOptions& options);
  // Codes `frame` as an I frame (intra), a P frame from `reference` (and the older anchors), or
  // a B frame from `reference` (list 0) and `reference1` (list 1); the reconstructed planes go
  // to *planes_out when given. `options` may differ from options_ in its thread count only.
  Result<SequenceFrame> code(const GeometryImage& frame, uint32_t number, bool intra,
                             const Planes* reference, const Planes* reference1,
                             const EncoderOptions& options, Planes* planes_out);
  // Whether B frames are coded on threads of their own while the next anchors are coded.
  bool frame_threads() const;
  // Moves the frames of outgoing_ that can leave to *done, front first: anchors, and B-frame
  // batches that are done, or that are waited for while more than `batches_left` batches
  // remain (0: every frame leaves). The first failed batch's error, after every batch ended.
  Status release(std::vector<SequenceFrame>* done, int batches_left);

  SequenceInfo info_;
  EncoderOptions options_;
  std::unique_ptr<RateController> rate_;
  std::unique_ptr<QualityController> quality_;
  std::shared_ptr<const Planes> anchor_;  // the last anchor's reconstructed planes
  // options.reference_frames() > 1: the anchors before anchor_ since the last I frame, nearest
  // first (at most refs - 1).
  std::deque<std::shared_ptr<const Planes>> older_anchors_;
  // The anchors' interpolated planes, made once and kept while frames predict from them (shared
  // by the background B frames, which reach the same plane objects through shared pointers).
  ReferenceInterpolationCache interpolation_;
  // Makes `planes` (frame `number`, an anchor) the last anchor.
  void set_anchor(std::shared_ptr<const Planes> planes, uint32_t number);
  struct Pending {
    uint32_t number;
    GeometryImage frame;
  };
  std::vector<Pending> pending_;  // B-frame candidates after the last anchor, display order
  // With frame threads: the coded frames not returned yet, in decode order; an anchor's frame,
  // or a batch of B frames (in display order) being coded in the background.
  struct Outgoing {
    std::vector<SequenceFrame> frames;  // the anchor (when batch is not valid)
    std::future<Result<std::vector<SequenceFrame>>> batch;
  };
  std::deque<Outgoing> outgoing_;
  int batches_ = 0;  // batches in outgoing_
  uint32_t next_number_ = 0;
};

}  // namespace gvkit::codec
