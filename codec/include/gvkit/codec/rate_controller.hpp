#pragma once
// Frame-level rate control for a target bitrate with a bounded buffer (encoder only; the stream
// carries each frame's QP). The model: the coded bits drain from a buffer of buffer_seconds x
// bitrate bits at bitrate / fps per frame. Each frame's QP comes from a per-type complexity
// estimate (bits ~ complexity 2^(-QP/6)) and a bit target that keeps the buffer half full (it
// starts half full: the decoder's initial delay);
// a frame that would overflow the buffer is re-encoded at a higher QP (up to 51).

#include <cstdint>

#include "gvkit/codec/encoder_options.hpp"

namespace gvkit::codec {

class RateController {
 public:
  // options.bitrate_kbps > 0 (contract); fps > 0.
  RateController(const EncoderOptions& options, double fps);

  // QP for the next frame (intra or predicted).
  int next_qp(bool intra) const;
  // Whether a frame of `bits` would overflow the buffer (re-encode at a higher QP if qp < 51).
  bool overflows(int64_t bits) const { return fullness_bits_ + bits - drain_bits_ > buffer_bits_; }
  // Accounts a coded frame of `bits` at `qp`.
  void update(bool intra, int qp, int64_t bits);

  double fullness_bits() const { return fullness_bits_; }
  double max_fullness_bits() const { return max_fullness_bits_; }
  double buffer_bits() const { return buffer_bits_; }

 private:
  double drain_bits_ = 0, buffer_bits_ = 0;
  double fullness_bits_ = 0, max_fullness_bits_ = 0;
  double complexity_[2] = {0, 0};  // bits x 2^(QP/6), per type (0 intra, 1 predicted)
  int last_qp_[2] = {0, 0};
  int qp_min_ = 0;
};

}  // namespace gvkit::codec
