// libFuzzer harness over the whole .gvid reader + decoder. Two entry points per input:
// 1. the bytes as a stream: open (header with version and profile, index or scan) and decode up
//    to 8 frames (format 2.0 of each profile, with the profile's packet rules, and legacy 1.x:
//    the seeds are tests/golden/v2, tests/golden/v1 and tests/fuzz/corpus/*_stream_seed);
// 2. the bytes after a 4-byte prefix as one plane's CABAC segment (intra, P, P with several
//    references or B, with or without a cross-plane source residual, inter partitions or the
//    initial context states of an X plane; unterminated segments with merge and TD16; the
//    quadratic intra mode; half-resolution frames reach the decoder through the stream entry),
//    decoded directly, so that mutations reach the macroblock layer without getting past the
//    CRCs.
// Every input must end in frames or a Status: a crash, hang, leak or sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/plane_coding.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace gvkit::codec;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  DecoderLimits limits;
  limits.max_pixels = 256 * 256;
  auto reader = GvidReader::open_memory(bytes, "fuzz", limits);
  if (reader.is_ok()) {
    const int64_t frames = std::min<int64_t>((*reader)->frame_count(), 8);
    for (int64_t i = 0; i < frames; ++i) (void)(*reader)->decode_frame(i);
  }
  if (size >= 4) {
    PlaneCodingParams params;
    params.bit_depth = 8 + data[2] % 9;
    params.lossless = (data[3] & 1) != 0;
    params.geometry_modes = (data[3] & 2) != 0;
    // Bits 4..5 of byte 2: the near-lossless delta of a bypass plane.
    params.near_lossless = params.lossless ? (data[2] >> 4) & 3 : 0;
    // Bit 6 of byte 2: temporal-difference prediction in a P plane.
    params.td_prediction = (data[2] & 0x40) != 0;
    // Bit 3 of byte 1: quarter-sample motion vectors in a P plane.
    params.subpel = (data[1] & 8) ? 4 : 0;
    params.qp_prime = (data[3] >> 2) % (52 + 6 * (params.bit_depth - 8));
    // Bits 4..5 of byte 1: larger transforms of a lossy plane: 0 = 4x4 only, 1 = up
    // to 8x8, 2 and 3 = up to 16x16.
    const int transforms = (data[1] >> 4) & 3;
    params.max_transform = params.lossless || transforms == 0 ? 4 : (transforms == 1 ? 8 : 16);
    // Bit 5 of byte 0: inter partitions in P planes (B planes ignore it).
    params.partitions = (data[0] & 0x20) != 0;
    // Bit 7 of byte 1: a segment of a compact packet (no end-of-plane bin: every 2.0 packet)
    // with merge in P planes (other planes ignore it) and, with TD prediction, TD16.
    params.end_of_plane_bin = (data[1] & 0x80) == 0;
    params.merge = (data[1] & 0x80) != 0;
    params.td16 = params.merge && params.td_prediction;
    // Bit 3 of byte 0: the quadratic 16x16 intra mode.
    params.quadratic_intra = (data[0] & 0x08) != 0;
    const int width = 16 * (1 + data[0] % 8), height = 16 * (1 + data[1] % 8);
    // Bit 7 of byte 2: a P plane, predicted from a ramp reference.
    SamplePlane reference;
    reference.width = width;
    reference.height = height;
    reference.samples.resize(static_cast<size_t>(width) * height);
    for (size_t i = 0; i < reference.samples.size(); ++i)
      reference.samples[i] = static_cast<uint16_t>((i * 37) & ((1u << params.bit_depth) - 1));
    // Bit 6 of byte 0 (intra and B planes; P planes: see below): a Y or Z plane with cross-plane
    // prediction from a source residual that is nonzero in every other macroblock
    // (the plane's residual is kept too).
    CrossPlaneResidual source, own;
    source.reset(width, height);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        if (((x / 16) + (y / 16)) % 2 == 0) {
          source.samples[static_cast<size_t>(y) * width + x] = (x * 7 + y * 3) % 41 - 20;
          source.mb_nonzero[static_cast<size_t>(y / 16) * (width / 16) + x / 16] = 1;
        }
    CrossPlaneLinks links;
    if (data[0] & 0x40) {
      links.source = &source;
      links.residual_out = &own;
    }
    // Bit 4 of byte 0: a Y or Z plane with cross-plane contexts, its initial context
    // states those the reference ramp's segment ended with, intra-coded as the X plane.
    CrossPlaneContextStates x_states;
    if (data[0] & 0x10) {
      PlaneCodingParams x_params = params;
      x_params.rdo = false;
      CrossPlaneLinks x_links;
      x_links.contexts_out = &x_states;
      (void)encode_plane(reference, x_params, nullptr, nullptr, nullptr, nullptr, &x_links);
      links.contexts = &x_states;
    }
    // Bit 7 of byte 0 with bit 7 of byte 2: a B plane, list 1 a second ramp.
    if ((data[0] & 0x80) && (data[2] & 0x80)) {
      SamplePlane reference1 = reference;
      for (size_t i = 0; i < reference1.samples.size(); ++i)
        reference1.samples[i] =
            static_cast<uint16_t>((i * 11 + 5) & ((1u << params.bit_depth) - 1));
      (void)decode_b_plane(std::string_view(bytes).substr(4), width, height, params, reference,
                           reference1, &links);
    } else if ((data[0] & 0x40) && (data[2] & 0x80)) {
      // Bit 6 of byte 0 with bit 7 of byte 2: a P plane with 2 + (byte 1 >> 4) % 4 references,
      // the older ones more ramps; bit 6 of byte 1: with the cross-plane source residual too
      // (several references, cross-plane prediction and larger transforms together).
      params.ref_count = 2 + (data[1] >> 4) % 4;
      std::vector<SamplePlane> older(params.ref_count - 1, reference);
      std::vector<const SamplePlane*> more;
      for (size_t k = 0; k < older.size(); ++k) {
        for (size_t i = 0; i < older[k].samples.size(); ++i)
          older[k].samples[i] =
              static_cast<uint16_t>((i * (13 + 6 * k) + k) & ((1u << params.bit_depth) - 1));
        more.push_back(&older[k]);
      }
      (void)decode_plane(std::string_view(bytes).substr(4), width, height, params, &reference,
                         nullptr, nullptr, &more, (data[1] & 0x40) ? &links : nullptr);
    } else {
      (void)decode_plane(std::string_view(bytes).substr(4), width, height, params,
                         (data[2] & 0x80) ? &reference : nullptr, nullptr, nullptr, nullptr,
                         &links);
    }
  }
  return 0;
}
