#pragma once
// SEI NAL units in an Annex B byte stream (H.264 / HEVC), for counting a peer's rate without
// them: x264 and x265 put a text banner of their version and every option (about 0.6 and 2.2 KB)
// into an SEI message of their first packet, data a decoder does not need.

#include <cstddef>
#include <cstdint>

namespace gvkit::bench {

enum class AnnexBCodec { kH264, kHevc };

// Bytes of the SEI NAL units in data[0, size) with their 3-byte start codes: H.264 nal_unit_type
// 6, HEVC 39 and 40 (prefix and suffix SEI). A NAL unit runs from the byte after its 00 00 01 to
// the next 00 00 01 or the end (the leading zero of a 4-byte start code counts with the unit
// before it). Bytes before the first start code belong to no unit; 0 when there is none.
int64_t annexb_sei_bytes(AnnexBCodec codec, const uint8_t* data, size_t size);

}  // namespace gvkit::bench
