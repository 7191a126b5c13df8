#include "packet_surgery.hpp"

#include <string_view>

#include <gtest/gtest.h>

#include "gvkit/codec/crc32.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::testing {

namespace format = codec::format;

size_t packet_header_size(std::string_view packet) {
  auto h = format::read_packet_header(packet);
  GVKIT_CHECK(h.is_ok());
  return h->header_size;
}

std::string packet_payload(const std::string& packet) {
  return packet.substr(packet_header_size(packet));
}

std::string first_packet(const std::string& stream, size_t header_bytes) {
  auto h = format::read_packet_header(std::string_view(stream).substr(header_bytes));
  GVKIT_CHECK(h.is_ok());
  return stream.substr(header_bytes, h->header_size + h->payload_size);
}

std::string with_flags2(std::string packet, uint8_t flags2) {
  auto h = format::read_packet_header(packet);
  GVKIT_CHECK(h.is_ok());
  h->flags2 = flags2;
  packet.replace(0, h->header_size, format::write_packet_header(*h));
  return packet;
}

std::string with_payload(const std::string& packet, std::string payload) {
  auto h = format::read_packet_header(packet);
  GVKIT_CHECK(h.is_ok());
  h->payload_size = static_cast<uint32_t>(payload.size());
  h->payload_crc = codec::crc32(payload);
  return format::write_packet_header(*h) + payload;
}

std::string damage_payload(std::string packet, std::mt19937& rng, int flips, size_t keep) {
  const size_t header = packet_header_size(packet);
  const size_t payload = packet.size() - header;
  GVKIT_CHECK(keep < payload);
  for (int k = 0; k < flips; ++k)
    packet[header + keep + rng() % (payload - keep)] ^= static_cast<char>(1 << (rng() % 8));
  return with_payload(packet, packet.substr(header));
}

std::string with_file_header_byte(const std::string& stream, size_t offset, uint8_t value) {
  size_t header_size = 0;
  GVKIT_CHECK(format::read_file_header(stream, &header_size).is_ok());
  GVKIT_CHECK(offset >= 4 && offset + 4 < header_size);
  std::string out = stream;
  out[offset] = static_cast<char>(value);
  const uint32_t crc = codec::crc32(out.data(), header_size - 4);
  for (int i = 0; i < 4; ++i) out[header_size - 4 + i] = static_cast<char>((crc >> (8 * i)) & 255);
  return out;
}

std::vector<std::string> stream_packets(const std::string& stream) {
  auto reader = codec::GvidReader::open_memory(stream, "x.gvid").value();
  size_t offset = static_cast<size_t>(reader->header_bytes());
  std::vector<std::string> out;
  for (int64_t k = 0; k < reader->frame_count(); ++k) {
    out.push_back(first_packet(stream, offset));
    offset += out.back().size();
  }
  return out;
}

std::string make_stream(const std::string& file_header, const std::vector<std::string>& packets) {
  std::string out = file_header;
  std::vector<format::IndexEntry> index;
  for (const std::string& packet : packets) {
    auto h = format::read_packet_header(packet);
    GVKIT_CHECK(h.is_ok());
    format::IndexEntry e;
    e.offset = out.size();
    e.frame_number = h->frame_number;
    e.payload_size = h->payload_size;
    e.type = h->type;
    e.header_size = static_cast<uint8_t>(h->header_size);
    index.push_back(e);
    out += packet;
  }
  return out + format::write_index(index, out.size());
}

std::vector<std::pair<format::FrameType, uint8_t>> payload_flags(const std::string& stream) {
  auto reader = codec::GvidReader::open_memory(stream, "x.gvid").value();
  size_t offset = static_cast<size_t>(reader->header_bytes());
  std::vector<std::pair<format::FrameType, uint8_t>> out;
  for (int64_t k = 0; k < reader->frame_count(); ++k) {
    auto h = format::read_packet_header(std::string_view(stream).substr(offset));
    EXPECT_TRUE(h.is_ok());
    if (!h.is_ok()) break;
    out.push_back({h->type, static_cast<uint8_t>(stream[offset + h->header_size])});
    offset += h->header_size + h->payload_size;
  }
  return out;
}

}  // namespace gvkit::testing
