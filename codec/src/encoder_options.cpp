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
  if (intra_period < 1 || intra_period > 100000)
    return invalid_argument("intra period " + std::to_string(intra_period) +
                            " out of range (1..100000)");
  if (search_range < 0 || search_range > 32)
    return invalid_argument("search range " + std::to_string(search_range) +
                            " out of range (0..32)");
  return Status::ok();
}

}  // namespace gvkit::codec
