#include "gvkit/codec/rate_controller.hpp"

#include <algorithm>
#include <cmath>

#include "gvkit/core/status.hpp"

namespace gvkit::codec {

RateController::RateController(const EncoderOptions& options, double fps) {
  GVKIT_CHECK(options.bitrate_kbps > 0 && fps > 0);
  drain_bits_ = options.bitrate_kbps * 1000.0 / fps;
  buffer_bits_ = options.bitrate_kbps * 1000.0 * options.buffer_seconds;
  qp_min_ = -6 * (options.bit_depth - 8);
  b_qp_offset_ = options.b_qp_offset;
  last_qp_[0] = last_qp_[1] = options.qp;
  // The decoder starts after half a buffer has arrived (a VBV-style initial delay), so the
  // buffer starts half full and the steering below keeps it there: no start-up spending spree.
  fullness_bits_ = max_fullness_bits_ = 0.5 * buffer_bits_;
}

int RateController::next_qp(format::FrameType frame_type) const {
  if (frame_type == format::FrameType::kBidirectional)
    return std::clamp((complexity_[1] > 0 ? last_qp_[1] : last_qp_[0]) + b_qp_offset_, qp_min_, 51);
  const bool intra = frame_type == format::FrameType::kIntra;
  const int type = intra ? 0 : 1;
  if (complexity_[type] <= 0) {
    // No frame of this type yet: an intra frame starts at the given QP, the first P frame at the
    // intra frame's.
    return std::clamp(last_qp_[0], qp_min_, 51);
  }
  // Steer the buffer towards half full within about eight frames; an intra frame may take up to
  // a quarter of the buffer on top (it is followed by cheap P frames).
  double target = drain_bits_ + (0.5 * buffer_bits_ - fullness_bits_) / 8.0;
  if (intra) target += 0.25 * buffer_bits_;
  target = std::max(target, 0.1 * drain_bits_);
  const int qp = static_cast<int>(std::lround(6.0 * std::log2(complexity_[type] / target)));
  // At most 6 QP steps from the last frame of the same type (stability).
  return std::clamp(std::clamp(qp, last_qp_[type] - 6, last_qp_[type] + 6), qp_min_, 51);
}

void RateController::update(format::FrameType frame_type, int qp, int64_t bits) {
  if (frame_type != format::FrameType::kBidirectional) {
    const int type = frame_type == format::FrameType::kIntra ? 0 : 1;
    complexity_[type] = static_cast<double>(bits) * std::pow(2.0, qp / 6.0);
    last_qp_[type] = qp;
  }
  fullness_bits_ = std::max(0.0, fullness_bits_ + static_cast<double>(bits) - drain_bits_);
  max_fullness_bits_ = std::max(max_fullness_bits_, fullness_bits_);
}

}  // namespace gvkit::codec
