#include "gvkit/codec/encoder_options.hpp"

namespace gvkit::codec {

const char* preset_name(Preset preset) { return preset == Preset::kFast ? "fast" : "slow"; }

Result<Preset> parse_preset(const std::string& name) {
  if (name == "fast") return Preset::kFast;
  if (name == "slow") return Preset::kSlow;
  return invalid_argument("preset '" + name + "' unknown (fast or slow)");
}

const char* value_prediction_name(ValuePrediction mode) {
  switch (mode) {
    case ValuePrediction::kOffset:
      return "offset";
    case ValuePrediction::kWeighted:
      return "weighted";
    case ValuePrediction::kAffine:
      return "affine";
    default:
      return "none";
  }
}

Result<ValuePrediction> parse_value_prediction(const std::string& name) {
  for (ValuePrediction m : {ValuePrediction::kNone, ValuePrediction::kOffset,
                            ValuePrediction::kWeighted, ValuePrediction::kAffine})
    if (name == value_prediction_name(m)) return m;
  return invalid_argument("value prediction '" + name +
                          "' unknown (none, offset, weighted or affine)");
}

const char* resolution_name(Resolution resolution) {
  switch (resolution) {
    case Resolution::kFull:
      return "full";
    case Resolution::kHalf:
      return "half";
    default:
      return "auto";
  }
}

Result<Resolution> parse_resolution(const std::string& name) {
  for (Resolution r : {Resolution::kFull, Resolution::kHalf, Resolution::kAuto})
    if (name == resolution_name(r)) return r;
  return invalid_argument("resolution '" + name + "' unknown (full, half or auto)");
}

Profile EncoderOptions::resolved_profile() const {
  if (profile != Profile::kAuto) return profile;
  if (bypass()) return Profile::kLossless;
  if (all_intra()) return Profile::kIntra;
  return Profile::kMain;
}

Status EncoderOptions::check() const {
  if (static_cast<int>(profile) > static_cast<int>(Profile::kMain))
    return invalid_argument("profile " + std::to_string(static_cast<int>(profile)) + " unknown");
  // What the profile forbids beyond what it implies (bypass(), all_intra()).
  if (profile == Profile::kIntra && bframes > 0)
    return invalid_argument("profile intra: I frames only, no B frames (bframes " +
                            std::to_string(bframes) + "; profile main has them)");
  if (profile == Profile::kIntra && refs > 1)
    return invalid_argument("profile intra: I frames only, no reference frames (refs " +
                            std::to_string(refs) + "; profile main has them)");
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
  if (subpel != 0 && subpel != 2 && subpel != 4)
    return invalid_argument("subpel " + std::to_string(subpel) +
                            " is not 0 (whole samples), 2 (half) or 4 (quarter)");
  if (search_range < 0 || search_range > 32)
    return invalid_argument("search range " + std::to_string(search_range) +
                            " out of range (0..32)");
  if (!(max_error_mm >= 0) || max_error_mm > 1e6)
    return invalid_argument("max error " + std::to_string(max_error_mm) +
                            " mm out of range (0 = off, else > 0)");
  if (lossless && max_error_mm > 0)
    return invalid_argument("max error: lossless and a max error exclude each other");
  for (int i = 0; i < 3; ++i)
    if (plane_qp_offset[i] < -12 || plane_qp_offset[i] > 12)
      return invalid_argument("plane QP offset " + std::to_string(plane_qp_offset[i]) +
                              " out of range (-12..12)");
  if (rdo_shortlist < 0 || rdo_shortlist > 13)
    return invalid_argument("RDO shortlist " + std::to_string(rdo_shortlist) +
                            " out of range (0 = every mode, else 1..13)");
  if (p_qp_offset < 0 || p_qp_offset > 12)
    return invalid_argument("P-frame QP offset " + std::to_string(p_qp_offset) +
                            " out of range (0..12)");
  if (bframes < -1 || bframes > 3)
    return invalid_argument("B frames " + std::to_string(bframes) +
                            " out of range (0..3 consecutive B frames, -1 automatic)");
  if (b_qp_offset < 0 || b_qp_offset > 12)
    return invalid_argument("B-frame QP offset " + std::to_string(b_qp_offset) +
                            " out of range (0..12)");
  if (!(bitrate_kbps >= 0) || bitrate_kbps > 1e7)
    return invalid_argument("bitrate " + std::to_string(bitrate_kbps) +
                            " kbit/s out of range (0 = constant QP)");
  if (bitrate_kbps > 0 && bypass())
    return invalid_argument(
        "bitrate: rate control needs lossy coding (not lossless, max error or profile lossless)");
  if (!(buffer_seconds >= 0.1) || buffer_seconds > 100)
    return invalid_argument("buffer " + std::to_string(buffer_seconds) +
                            " s out of range (0.1..100)");
  if (!(target_psnr_db >= 0) || target_psnr_db > 200)
    return invalid_argument("target PSNR " + std::to_string(target_psnr_db) +
                            " dB out of range (0 = off, else up to 200)");
  if (!(target_rms_mm >= 0) || target_rms_mm > 1e6)
    return invalid_argument("target RMS " + std::to_string(target_rms_mm) +
                            " mm out of range (0 = off, else > 0)");
  if (!(intra_target_offset_db >= 0) || intra_target_offset_db > 20)
    return invalid_argument("intra target offset " + std::to_string(intra_target_offset_db) +
                            " dB out of range (0..20)");
  if (target_psnr_db > 0 && target_rms_mm > 0)
    return invalid_argument("target PSNR: a target PSNR and a target RMS exclude each other");
  if (constant_quality() && bitrate_kbps > 0)
    return invalid_argument(std::string(target_psnr_db > 0 ? "target PSNR" : "target RMS") +
                            ": constant quality and a bitrate exclude each other");
  if (constant_quality() && bypass())
    return invalid_argument(
        std::string(target_psnr_db > 0 ? "target PSNR" : "target RMS") +
        ": constant quality needs lossy coding (not lossless, max error or profile "
        "lossless)");
  if (refs < -1 || refs == 0 || refs > 5)
    return invalid_argument("refs " + std::to_string(refs) +
                            " out of range (1..5 reference frames, -1 automatic)");
  if (max_transform != 4 && max_transform != 8 && max_transform != 16)
    return invalid_argument("max transform " + std::to_string(max_transform) +
                            " is not 4, 8 or 16");
  if (deblock.beta < 1 || deblock.beta > 255 || deblock.tc < 1 || deblock.tc > 255)
    return invalid_argument("deblocking strength " + std::to_string(deblock.beta) + "/" +
                            std::to_string(deblock.tc) + " out of range (1..255 each)");
  if (resolution == Resolution::kHalf && bypass())
    return invalid_argument(
        "resolution half: lossless and max-error coding (profile lossless) are at full "
        "resolution only");
  if (threads < 1 || threads > 16)
    return invalid_argument("threads " + std::to_string(threads) + " out of range (1..16)");
  return Status::ok();
}

}  // namespace gvkit::codec
