#pragma once
// Packet surgery for the codec's corrupt-input tests: take a frame packet out of a .gvid stream,
// change its header's flags, replace or damage its payload with the header's size and CRC fixed
// up, so that the change reaches the payload parser and the macroblock layer instead of being
// caught by the CRC check. Test code only (not part of the codec).

#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gvkit/codec/gvid_format.hpp"

namespace gvkit::testing {

// The length of `packet`'s header (24 full, 13-21 compact), and its payload. Contract: a
// readable packet header.
size_t packet_header_size(std::string_view packet);
std::string packet_payload(const std::string& packet);

// The first frame packet (header + payload) of `stream`, whose file header and index take
// `header_bytes`. Contract: a stream with a readable packet there.
std::string first_packet(const std::string& stream, size_t header_bytes);

// `packet` with its header's flags2 byte set to `flags2` (the CRC covers the payload only).
std::string with_flags2(std::string packet, uint8_t flags2);

// `packet`'s header with `payload` as the payload (size and CRC rewritten).
std::string with_payload(const std::string& packet, std::string payload);

// The first byte of every packet's payload (plane count and payload flags) in decode order, with
// the packet's frame type. EXPECTs readable packet headers.
std::vector<std::pair<codec::format::FrameType, uint8_t>> payload_flags(const std::string& stream);

// The file header of `stream` (its first header_bytes bytes) with byte `offset` set to `value`
// and the header's CRC fixed up (version, profile and reserved bytes). Contract: a readable
// header.
std::string with_file_header_byte(const std::string& stream, size_t offset, uint8_t value);

// The frame packets of `stream` in decode order (header + payload each). Contract: a readable
// stream.
std::vector<std::string> stream_packets(const std::string& stream);

// A stream of `file_header` and `packets` (decode order) with a fresh index and trailer.
// Contract: readable packet headers.
std::string make_stream(const std::string& file_header, const std::vector<std::string>& packets);

// `packet` with `flips` random bits of its payload flipped, none in the payload's first `keep`
// bytes (keep < payload size), and the CRC fixed up. Draws from `rng`.
std::string damage_payload(std::string packet, std::mt19937& rng, int flips, size_t keep);

}  // namespace gvkit::testing
