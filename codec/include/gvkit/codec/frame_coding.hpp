#pragma once
// One frame <-> one .gvid frame packet (packet header + payload of per-plane CABAC segments).

#include <cstdint>
#include <string>
#include <string_view>

#include "gvkit/codec/encoder_options.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/sequence_info.hpp"
#include "gvkit/core/geometry_image.hpp"

namespace gvkit::codec {

struct EncodedFrame {
  std::string packet;            // header + payload
  GeometryImage reconstruction;  // exactly what a decoder will output
};

// Encodes an intra frame. Fails (naming the frame) when its size differs from the header's.
Result<EncodedFrame> encode_frame(const GeometryImage& image, const SequenceInfo& info,
                                  const EncoderOptions& options, uint32_t frame_number);

// Limits a decoder puts on what a stream may ask of it.
struct DecoderLimits {
  int64_t max_pixels = int64_t{1} << 24;  // width * height
};

// Decodes a complete packet (header + payload). Fails naming the field on any inconsistency:
// "packet header CRC mismatch", "payload CRC mismatch", "plane Y: macroblock (3, 1): ...".
Result<GeometryImage> decode_frame_packet(std::string_view packet, const SequenceInfo& info,
                                          int64_t frame_number);

}  // namespace gvkit::codec
