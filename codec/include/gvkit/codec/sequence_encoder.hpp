#pragma once
// SequenceEncoder: the frame order of a .gvid encode. Frames come in display order; anchors (I
// and P frames, EncoderOptions::is_anchor) are coded when they arrive, and the B-frame
// candidates between two anchors wait for the second one and are then coded as B frames
// predicted from both (format 1.5). Coded frames leave in decode order: an anchor, then the B
// frames before it. Candidates still waiting at the end (no anchor follows) are coded as P
// frames by flush(). With bframes = 0 every frame is coded when it arrives, as in format 1.4.

#include <cstdint>
#include <deque>
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

  // Takes the next frame in display order; returns the frames this completes, in decode order
  // (none while it waits as a B-frame candidate). Fails naming the frame on bad input.
  Result<std::vector<SequenceFrame>> push(const GeometryImage& frame);
  // Codes the frames still waiting, as P frames, in display order.
  Result<std::vector<SequenceFrame>> flush();

  // Frames pushed so far.
  int64_t frames_pushed() const { return next_number_; }
  // The rate controller when options.bitrate_kbps > 0, else null.
  const RateController* rate_controller() const { return rate_.get(); }
  // The constant-quality search when options.constant_quality(), else null.
  const QualityController* quality_controller() const { return quality_.get(); }

 private:
  SequenceEncoder(const SequenceInfo& info, const EncoderOptions& options);
  Result<SequenceFrame> code(const GeometryImage& frame, uint32_t number, bool intra,
                             const std::vector<SamplePlane>* reference1,
                             std::vector<SamplePlane>* planes_out);

  SequenceInfo info_;
  EncoderOptions options_;
  std::unique_ptr<RateController> rate_;
  std::unique_ptr<QualityController> quality_;
  std::vector<SamplePlane> anchor_;  // the last anchor's reconstructed planes
  // options.reference_frames() > 1: the anchors before anchor_ since the last I frame, nearest
  // first (at most refs - 1).
  std::deque<std::vector<SamplePlane>> older_anchors_;
  // The anchors' interpolated planes, made once and kept while frames predict from them.
  ReferenceInterpolationCache interpolation_;
  // Makes `planes` (frame `number`, an anchor) the last anchor.
  void set_anchor(std::vector<SamplePlane> planes, uint32_t number);
  struct Pending {
    uint32_t number;
    GeometryImage frame;
  };
  std::vector<Pending> pending_;  // B-frame candidates after the last anchor, display order
  uint32_t next_number_ = 0;
};

}  // namespace gvkit::codec
