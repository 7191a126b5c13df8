#include "gvkit/codec/encoder_tune.hpp"

#include <cerrno>
#include <cstdlib>
#include <functional>
#include <sstream>

namespace gvkit::codec {
namespace {

using Setter = std::function<Status(const std::string& value, EncoderOptions& o)>;

struct Entry {
  TuneKey key;
  Setter set;
};

Status bad_value(const std::string& why) { return invalid_argument(why); }

Result<bool> parse_bool(const std::string& v) {
  if (v == "on" || v == "true" || v == "yes" || v == "1") return true;
  if (v == "off" || v == "false" || v == "no" || v == "0") return false;
  return bad_value("not on or off");
}

Result<int> parse_int(const std::string& v) {
  errno = 0;
  char* end = nullptr;
  const long n = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0' || errno != 0 || n < -1000000 || n > 1000000)
    return bad_value("not an integer");
  return static_cast<int>(n);
}

Result<double> parse_double(const std::string& v) {
  errno = 0;
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || errno != 0) return bad_value("not a number");
  return x;
}

Setter flag(bool EncoderOptions::*field) {
  return [field](const std::string& v, EncoderOptions& o) -> Status {
    GVKIT_ASSIGN_OR_RETURN(o.*field, parse_bool(v));
    return Status::ok();
  };
}

Setter integer(int EncoderOptions::*field) {
  return [field](const std::string& v, EncoderOptions& o) -> Status {
    GVKIT_ASSIGN_OR_RETURN(o.*field, parse_int(v));
    return Status::ok();
  };
}

Setter real(double EncoderOptions::*field) {
  return [field](const std::string& v, EncoderOptions& o) -> Status {
    GVKIT_ASSIGN_OR_RETURN(o.*field, parse_double(v));
    return Status::ok();
  };
}

const std::vector<Entry>& entries() {
  static const std::vector<Entry> table = {
      {{"geometry-modes", "on|off", "the four geometry 4x4 intra modes (frame flag bit 1)"},
       flag(&EncoderOptions::geometry_modes)},
      {{"td", "on|off",
        "P frames: temporal-difference prediction, inter + intra-predicted difference (frame "
        "flag bit 6)"},
       flag(&EncoderOptions::td_prediction)},
      {{"td16", "on|off",
        "P frames with TD: predict the temporal difference with one 16x16 mode (payload bit 6)"},
       flag(&EncoderOptions::td16)},
      {{"merge", "on|off",
        "P frames: skip and 16x16 inter macroblocks may take a neighbour's vector (payload bit "
        "5)"},
       flag(&EncoderOptions::merge)},
      {{"quadratic-intra", "on|off",
        "I16x16 macroblocks may predict with a least-squares quadratic surface (payload bit 7)"},
       flag(&EncoderOptions::quadratic_intra)},
      {{"cross-plane", "on|off",
        "Y and Z macroblocks may add a scaled copy of the X residual (flags2 bit 3)"},
       flag(&EncoderOptions::cross_plane)},
      {{"cross-plane-contexts", "on|off",
        "Y and Z start their CABAC contexts from X's final states (flags2 bit 4)"},
       flag(&EncoderOptions::cross_plane_contexts)},
      {{"temporal-contexts", "on|off",
        "P and B frames start every plane's contexts from the reference's final states (flags2 "
        "bit 7)"},
       flag(&EncoderOptions::temporal_contexts)},
      {{"partitions", "on|off",
        "slow preset, P frames: 16x8, 8x16 and 8x8 inter partitions (flags2 bit 5)"},
       flag(&EncoderOptions::partitions)},
      {{"deblock", "on|off", "lossy frames: the in-loop deblocking filter (flags2 bit 6)"},
       flag(&EncoderOptions::deblocking)},
      {{"deblock-beta", "1..255",
        "deblocking edge threshold in quarter quantizer steps (default 6)"},
       [](const std::string& v, EncoderOptions& o) -> Status {
         GVKIT_ASSIGN_OR_RETURN(o.deblock.beta, parse_int(v));
         return Status::ok();
       }},
      {{"deblock-tc", "1..255", "deblocking clipping in sixteenths of a step (default 4)"},
       [](const std::string& v, EncoderOptions& o) -> Status {
         GVKIT_ASSIGN_OR_RETURN(o.deblock.tc, parse_int(v));
         return Status::ok();
       }},
      {{"max-transform", "4|8|16",
        "largest residual transform of lossy inter and I16x16 macroblocks (flags2 bit 2 above "
        "4)"},
       integer(&EncoderOptions::max_transform)},
      {{"resolution", "auto|full|half",
        "lossy frames at half resolution, upsampled 2x by the decoder: per I frame (auto), "
        "never or always (packet type bit 4)"},
       [](const std::string& v, EncoderOptions& o) -> Status {
         GVKIT_ASSIGN_OR_RETURN(o.resolution, parse_resolution(v));
         return Status::ok();
       }},
      {{"bframes", "-1..3",
        "consecutive B frames between anchors; -1 automatic (1 lossy, 0 lossless)"},
       integer(&EncoderOptions::bframes)},
      {{"refs", "-1, 1..5",
        "reference frames of P frames (flags2 bit 1 above 1); -1 automatic (3 lossy, 1 "
        "lossless)"},
       integer(&EncoderOptions::refs)},
      {{"subpel", "0|2|4", "motion vector precision: whole, half or quarter samples"},
       integer(&EncoderOptions::subpel)},
      {{"shared-motion", "on|off",
        "P frames: Y and Z may take over X's vector with one flag (flags2 bit 0)"},
       flag(&EncoderOptions::shared_motion)},
      {{"value-prediction", "none|offset|weighted|affine",
        "P frames: a per-frame map of the reference's xyz before motion compensation (frame "
        "flag bit 4)"},
       [](const std::string& v, EncoderOptions& o) -> Status {
         GVKIT_ASSIGN_OR_RETURN(o.value_prediction, parse_value_prediction(v));
         return Status::ok();
       }},
      {{"plane-qp-offsets", "X,Y,Z",
        "QP offsets of the X, Y, Z planes, -12..12 each (frame flag bit 5)"},
       [](const std::string& v, EncoderOptions& o) -> Status {
         std::stringstream in(v);
         std::string part;
         int values[3], n = 0;
         while (std::getline(in, part, ',')) {
           if (n == 3) return bad_value("three integers X,Y,Z");
           auto x = parse_int(part);
           if (!x.is_ok()) return bad_value("three integers X,Y,Z");
           values[n++] = *x;
         }
         if (n != 3) return bad_value("three integers X,Y,Z");
         for (int i = 0; i < 3; ++i) o.plane_qp_offset[i] = values[i];
         return Status::ok();
       }},
      {{"texture-qp", "-1, 0..51",
        "the texture plane's QP in I frames, 8-bit units (default 24; -1 = the frame QP)"},
       integer(&EncoderOptions::texture_qp)},
      {{"p-qp-offset", "0..12", "added to the QP in P frames (default 4)"},
       integer(&EncoderOptions::p_qp_offset)},
      {{"b-qp-offset", "0..12", "added to the P frames' QP in B frames (default 2)"},
       integer(&EncoderOptions::b_qp_offset)},
      {{"search-range", "0..32", "full-search integer motion range in samples (default 4)"},
       integer(&EncoderOptions::search_range)},
      {{"rdoq", "on|off", "encoder only: rate-distortion optimised quantization of lossy blocks"},
       flag(&EncoderOptions::rdoq)},
      {{"intra-rdo", "on|off",
        "encoder only, fast preset: lossy I frames decided by RDO on a mode shortlist"},
       flag(&EncoderOptions::intra_rdo)},
      {{"decimation", "on|off",
        "encoder only, lossy P frames: inter dead zone, sparse +-1 blocks dropped"},
       flag(&EncoderOptions::inter_decimation)},
      {{"joint-motion-search", "on|off",
        "encoder only, shared motion: X's vectors searched on the error of all three planes"},
       flag(&EncoderOptions::joint_motion_search)},
      {{"rdo-shortlist", "0..13",
        "encoder only, slow preset: RDO on this many intra modes per block, the cheapest by "
        "SATD (0 = every mode; default 3)"},
       integer(&EncoderOptions::rdo_shortlist)},
      {{"transform-early-exit", "on|off",
        "encoder only, slow preset: transform sizes tried from the largest down, stopping early"},
       flag(&EncoderOptions::transform_early_exit)},
      {{"outline-weight", "1..64",
        "encoder only, lossy frames: the outline's samples count this many times in the "
        "rate-distortion decisions (default 8; 1 = plain SSD)"},
       integer(&EncoderOptions::outline_weight)},
      {{"skip-check", "on|off",
        "encoder only: try the predicted vector first, take a skip found there at once"},
       flag(&EncoderOptions::skip_check)},
      {{"td-whole-retry", "on|off",
        "encoder only, fast preset: TD tried again at the whole-sample vector where TD beat plain "
        "inter (default off; the slow preset always tries it)"},
       flag(&EncoderOptions::td_whole_retry)},
      {{"buffer-seconds", "0.1..100", "rate control (--bitrate): buffer in seconds (default 1)"},
       real(&EncoderOptions::buffer_seconds)},
      {{"target-rms-mm", "> 0",
        "constant quality by RMS point error (mm) instead of --quality's PSNR"},
       real(&EncoderOptions::target_rms_mm)},
      {{"intra-target-offset", "0..20",
        "constant quality: I frames aim this many dB above the target"},
       real(&EncoderOptions::intra_target_offset_db)},
  };
  return table;
}

}  // namespace

const std::vector<TuneKey>& tune_keys() {
  static const std::vector<TuneKey> keys = [] {
    std::vector<TuneKey> k;
    for (const Entry& e : entries()) k.push_back(e.key);
    return k;
  }();
  return keys;
}

Status apply_tune(const std::string& key, const std::string& value, EncoderOptions* options) {
  const std::string what = "tune " + key + "=" + value;
  for (const Entry& e : entries())
    if (key == e.key.name) {
      EncoderOptions o = *options;
      const Status s = e.set(value, o);
      if (!s.is_ok())
        return invalid_argument(what + ": " + s.message() + " (" + e.key.values + ")");
      *options = o;
      return Status::ok();
    }
  return invalid_argument(what + ": unknown key ('gvkit encode --tune help' lists the keys)");
}

Status apply_tune(const std::string& key_value, EncoderOptions* options) {
  const size_t eq = key_value.find('=');
  if (eq == std::string::npos || eq == 0)
    return invalid_argument("tune '" + key_value + "': not key=value");
  return apply_tune(key_value.substr(0, eq), key_value.substr(eq + 1), options);
}

}  // namespace gvkit::codec
