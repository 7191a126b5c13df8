#pragma once
// Options of the .gvid encoder, bound to the flags of `gvkit encode`.

#include <cstdint>
#include <string>

#include "gvkit/core/status.hpp"

namespace gvkit::codec {

enum class Preset {
  kFast,  // SATD-based mode decision, no 8x8 transform
  kSlow,  // rate-distortion optimised (SSD + lambda * CABAC bits) over every block type
};

const char* preset_name(Preset preset);
Result<Preset> parse_preset(const std::string& name);

struct EncoderOptions {
  int qp = 12;                 // QP in 8-bit units, -6 (B - 8) .. 51; coded as QP' = QP + 6 (B - 8)
  bool lossless = false;       // transform bypass: decoded samples equal the quantized input
  int bit_depth = 16;          // B, 8..16
  bool geometry_modes = true;  // the four geometry 4x4 intra modes
  bool intra_only = false;     // every frame intra; else an I frame every intra_period, P between
  int intra_period = 30;       // frames from one I frame to the next (1 = intra only)
  int search_range = 4;        // full-search integer motion range of P frames (samples), 0..32
  Preset preset = Preset::kSlow;

  // Ok when every value is in range; the message names the option.
  Status check() const;
  // QP' of the X, Y, Z planes.
  int qp_prime() const { return qp + 6 * (bit_depth - 8); }
  // Whether frame `frame_number` is coded as an I frame.
  bool is_intra(int64_t frame_number) const {
    return intra_only || intra_period <= 1 || frame_number % intra_period == 0;
  }
};

}  // namespace gvkit::codec
