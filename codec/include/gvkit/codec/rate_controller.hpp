#pragma once
// Frame-level rate control for a target bitrate with a bounded buffer (encoder only; the stream
// carries each frame's QP). The model: the coded bits drain from a buffer of buffer_seconds x
// bitrate bits at bitrate / fps per frame. Each frame's QP comes from a per-type complexity
// estimate (bits ~ complexity 2^(-QP/6)) and a bit target that keeps the buffer half full (it
// starts half full: the decoder's initial delay);
// a frame that would overflow the buffer is re-encoded at a higher QP (up to 51). B frames
// (format 1.5) take the last P frame's QP + options.b_qp_offset (their bits are still
// accounted): a B frame is no reference, so it is coded coarser than the anchors around it.

#include <cstdint>

#include "gvkit/codec/encoder_options.hpp"
#include "gvkit/codec/gvid_format.hpp"

namespace gvkit::codec {

class RateController {
 public:
  // options.bitrate_kbps > 0 (contract); fps > 0.
  RateController(const EncoderOptions& options, double fps);

  // QP for the next frame (in decode order) of the given type.
  int next_qp(format::FrameType type) const;
  int next_qp(bool intra) const {
    return next_qp(intra ? format::FrameType::kIntra : format::FrameType::kPredicted);
  }
  // Whether a frame of `bits` would overflow the buffer (re-encode at a higher QP if qp < 51).
  bool overflows(int64_t bits) const { return fullness_bits_ + bits - drain_bits_ > buffer_bits_; }
  // Accounts a coded frame of `bits` at `qp`.
  void update(format::FrameType type, int qp, int64_t bits);
  void update(bool intra, int qp, int64_t bits) {
    update(intra ? format::FrameType::kIntra : format::FrameType::kPredicted, qp, bits);
  }

  double fullness_bits() const { return fullness_bits_; }
  double max_fullness_bits() const { return max_fullness_bits_; }
  double buffer_bits() const { return buffer_bits_; }

 private:
  double drain_bits_ = 0, buffer_bits_ = 0;
  double fullness_bits_ = 0, max_fullness_bits_ = 0;
  double complexity_[2] = {0, 0};  // bits x 2^(QP/6), per type (0 intra, 1 predicted)
  int last_qp_[2] = {0, 0};
  int qp_min_ = 0;
  int b_qp_offset_ = 0;
};

}  // namespace gvkit::codec
