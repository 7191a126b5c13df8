#pragma once
// Profiles of the .gvid format 2.0 (docs/bitstream.md 1.2): named tool sets, signalled in the
// file header's profile_idc byte as H.264 signals its profiles. A profile says what a decoder
// must support to decode the stream and constrains every frame packet in it; the tools inside a
// profile stay per-frame switches in the packet header and payload flags.

#include <cstdint>
#include <string>

#include "gvkit/core/status.hpp"

namespace gvkit::codec {

enum class Profile : uint8_t {
  // Encoder option only (never in a stream): lossless when the options code every frame by
  // transform bypass, intra when every frame is an I frame, else main
  // (EncoderOptions::resolved_profile).
  kAuto = 0,
  // Every frame transform-bypass (frame flag bit 0): exact, or within a max error per point
  // (near-lossless); I, P and B frames; no transforms, deblocking or half resolution.
  kLossless = 1,
  kIntra = 2,  // I frames only (lossy or transform-bypass): no motion compensation
  kMain = 3,   // every frame type and every tool
};

// "auto", "lossless", "intra" or "main" ("?" for values outside the enum).
const char* profile_name(Profile profile);
// The profile named `name` (one of the names above); invalid_argument naming it otherwise.
Result<Profile> parse_profile(const std::string& name);
// The profile of a format 2.0 header's profile_idc byte (1, 2 or 3); unsupported otherwise,
// naming the value.
Result<Profile> profile_from_idc(uint8_t idc);

}  // namespace gvkit::codec
