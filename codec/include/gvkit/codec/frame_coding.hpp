#pragma once
// One frame <-> one .gvid frame packet (packet header + payload of per-plane CABAC segments).

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "gvkit/codec/encoder_options.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/plane_coding.hpp"
#include "gvkit/codec/sequence_info.hpp"
#include "gvkit/core/geometry_image.hpp"

namespace gvkit::codec {

struct EncodedFrame {
  std::string packet;               // header + payload
  GeometryImage reconstruction;     // exactly what a decoder will output
  std::vector<SamplePlane> planes;  // the reconstructed coded planes (reference of a P frame)
  std::vector<PlaneCodingStats> plane_stats;  // per coded plane: where its bits went
};

// Encodes an intra frame, a P frame predicted from `reference` (the previous anchor's
// reconstructed planes) when given, or with `reference1` too (the next anchor's planes) a B
// frame (format 1.5; QP: qp + p_qp_offset + b_qp_offset). A P frame with options.reference_frames()
// > 1 and `older` (the reconstructed planes of the anchors before `reference` since the last I
// frame, nearest first) predicts from up to that many of them (format 1.6, flags2 bit 1). Fails
// (naming the frame) when its size differs from the header's. `cache` (optional): the encoder's
// store of interpolated references (interpolation_cache.hpp; the packet does not depend on it).
// The reconstructed planes carry their segments' final context states; with
// options.temporal_contexts a P or B frame whose `reference` planes carry them starts from them
// (format 1.9).
Result<EncodedFrame> encode_frame(
    const GeometryImage& image, const SequenceInfo& info, const EncoderOptions& options,
    uint32_t frame_number, const std::vector<SamplePlane>* reference = nullptr,
    const std::vector<SamplePlane>* reference1 = nullptr,
    const std::vector<const std::vector<SamplePlane>*>* older = nullptr,
    ReferenceInterpolationCache* cache = nullptr);

// Near-lossless residual bound (samples) that keeps the point error within max_error_mm at the
// sequence's quantization step: 0 when off (or when only exact coding fits), -1 when even the
// input quantization exceeds it.
int near_lossless_delta(const SequenceInfo& info, double max_error_mm);

// The reference frames a packet predicts from: 0 for an I frame, 2 for a B frame, 1 for a P
// frame, or its ref_count with several references (format 1.6). Fails on a damaged header or
// payload prefix.
Result<int> packet_reference_count(std::string_view packet);

// Limits a decoder puts on what a stream may ask of it.
struct DecoderLimits {
  int64_t max_pixels = int64_t{1} << 24;  // width * height
};

// Decodes a complete packet (header + payload). Fails naming the field on any inconsistency:
// "packet header CRC mismatch", "payload CRC mismatch", "plane Y: macroblock (3, 1): ...".
// A P packet needs `reference` (the previous anchor's decoded planes), a B packet `reference`
// and `reference1` (the anchors before and after it in display order; "B frame without the
// anchor frame after it" otherwise); planes_out (optional) receives this frame's decoded planes,
// the reference of the next. A P packet with several references (format 1.6) also needs
// `older`: the anchors before `reference` since the last intra frame, nearest first (at least
// ref_count - 1 of them; "ref_count 3 names more reference frames than the 2 anchor frames
// since the last intra frame" otherwise). The decoded planes carry their segments' final context
// states (SamplePlane::final_contexts), which a packet with temporal contexts (format 1.9,
// flags2 bit 7) needs on `reference`'s planes: planes from elsewhere fail it with
// failed_precondition. texture_qp_offset: the plane QP offsets (flag bit 5) of a frame with a
// texture plane carry its offset too (format 2.0); false for format 1.x packets (X, Y, Z only).
Result<GeometryImage> decode_frame_packet(
    std::string_view packet, const SequenceInfo& info, int64_t frame_number,
    const std::vector<SamplePlane>* reference = nullptr,
    std::vector<SamplePlane>* planes_out = nullptr,
    const std::vector<SamplePlane>* reference1 = nullptr,
    const std::vector<const std::vector<SamplePlane>*>* older = nullptr,
    bool texture_qp_offset = true);

// decode_frame_packet without the geometry image: the frame's decoded planes (at half
// resolution when the packet codes it so), each carrying what a later packet predicts from.
// Fails as decode_frame_packet does.
Result<std::vector<SamplePlane>> decode_frame_planes(
    std::string_view packet, const SequenceInfo& info,
    const std::vector<SamplePlane>* reference = nullptr,
    const std::vector<SamplePlane>* reference1 = nullptr,
    const std::vector<const std::vector<SamplePlane>*>* older = nullptr,
    bool texture_qp_offset = true);

// The geometry image of a frame's decoded planes (decode_frame_planes' result): upsampled to
// the header's size when they are at half resolution, then dequantized (dequantize_geometry).
// decode_frame_packet returns exactly this. Preconditions: at least 3 planes, of info's sizes.
// With `into`: written into *into's pixel buffers as dequantize_geometry_into does, and returned
// as a second header of the same buffers.
GeometryImage decoded_geometry(const std::vector<SamplePlane>& planes, const SequenceInfo& info,
                               int64_t frame_number, GeometryImage* into = nullptr);

}  // namespace gvkit::codec
