#pragma once
// Peer codecs through libavcodec, intra-only or with a GOP (PeerConfig::gop), on the same quantized
// planes as ours: each frame is three B-bit planes (X, Y, Z) given as Y, U, V (4:4:4) or G, B, R.
// The caller quantizes by rounding (quantize_geometry), so no FFmpeg conversion or dithering is
// involved.

#include <string>
#include <utility>
#include <vector>

#include "gvkit/codec/plane_coding.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::bench {

struct PeerConfig {
  std::string encoder;  // "libx265", "libx264", "ffv1"
  std::string pix_fmt;  // "yuv444p12le", "yuv444p10le", "gbrp16le"
  int bit_depth = 12;
  std::vector<std::pair<std::string, std::string>> options;  // private encoder options
  int gop = 1;      // frames from one intra frame to the next (1 = intra only)
  int bframes = 0;  // consecutive B frames (0 = none)
};

struct PeerRun {
  // Per packet, without SEI NAL units (H.264 / HEVC: the encoders' option banners and other
  // messages a decoder does not need); sei_bytes is what was left out, all packets together.
  std::vector<int64_t> frame_bytes;
  int64_t sei_bytes = 0;
  std::vector<std::vector<codec::SamplePlane>> decoded;  // per frame, 3 planes (width x height)
  double encode_seconds = 0, decode_seconds = 0;
};

// frames[f][p]: plane p of frame f, at least width x height samples. Fails with libav's message.
// Says on stderr how many SEI bytes it left out of frame_bytes, when there were any.
Result<PeerRun> run_peer(const std::vector<std::vector<codec::SamplePlane>>& frames, int width,
                         int height, const PeerConfig& config);

}  // namespace gvkit::bench
