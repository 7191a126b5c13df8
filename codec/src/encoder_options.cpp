#include "gvkit/codec/encoder_options.hpp"

namespace gvkit::codec {

const char* preset_name(Preset preset) { return preset == Preset::kFast ? "fast" : "slow"; }

Result<Preset> parse_preset(const std::string& name) {
  if (name == "fast") return Preset::kFast;
  if (name == "slow") return Preset::kSlow;
  return invalid_argument("preset '" + name + "' unknown (fast or slow)");
}

Status EncoderOptions::check() const {
  if (bit_depth < 8 || bit_depth > 16)
    return invalid_argument("bit depth " + std::to_string(bit_depth) + " out of range (8..16)");
  const int qp_min = -6 * (bit_depth - 8);
  if (!lossless && (qp < qp_min || qp > 51))
    return invalid_argument("qp " + std::to_string(qp) + " out of range (" +
                            std::to_string(qp_min) + "..51 at " + std::to_string(bit_depth) +
                            " bits)");
  if (!intra_only)
    return unsupported("inter frames are not implemented in this version (use intra_only)");
  return Status::ok();
}

}  // namespace gvkit::codec
