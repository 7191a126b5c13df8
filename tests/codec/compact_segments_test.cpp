// Compact segment sizes (the payload's first byte bit 4, docs/bitstream.md 2.1; every format 2.0
// packet): streams round-trip with and without texture with the bit set in every packet, and
// payloads with flag bits out of place or sizes that do not fit are rejected with a message.
// (The legacy u32 sizes are read by the v1 golden streams.)
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "packet_surgery.hpp"

namespace gvkit::codec {
namespace {

// The first payload byte of every packet, in stream order.
std::vector<uint8_t> planes_bytes(const std::string& stream) {
  size_t offset =
      static_cast<size_t>(GvidReader::open_memory(stream, "x.gvid").value()->header_bytes());
  std::vector<uint8_t> out;
  while (offset < stream.size()) {
    auto header = format::read_packet_header(std::string_view(stream).substr(offset));
    if (!header.is_ok()) break;  // the index
    out.push_back(static_cast<uint8_t>(stream[offset + header->header_size]));
    offset += header->header_size + header->payload_size;
  }
  EXPECT_FALSE(out.empty());
  return out;
}

TEST(CompactSegments, StreamsRoundTripWithCompactSizesInEveryPacket) {
  auto frames = testing::make_moving_analytic_video(48, 5);
  for (const bool texture : {false, true}) {
    if (texture)
      for (GeometryImage& f : frames) f.texture = cv::Mat(48, 48, CV_32F, cv::Scalar(0.35));
    const SequenceInfo info = testing::info_for(frames);
    for (const bool lossless : {false, true}) {
      SCOPED_TRACE(std::string(texture ? "texture" : "xyz") + (lossless ? ", lossless" : ""));
      EncoderOptions o;
      o.lossless = lossless;
      o.qp = 12;
      const std::string stream = testing::writer_round_trip(frames, info, o);
      const size_t planes = texture ? 4 : 3;
      for (const uint8_t v : planes_bytes(stream)) {
        EXPECT_EQ(v & format::kPayloadPlaneCount, planes);
        EXPECT_TRUE(v & format::kPayloadCompactSegments);
      }
    }
  }
}

TEST(CompactSegments, BadPayloadsAreRejected) {
  const auto frames = testing::make_moving_analytic_video(32, 1);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.intra_only = true;
  o.qp = 6;
  const std::string stream = encode_gvid(frames, info, o).value();
  const std::string packet = testing::first_packet(
      stream, GvidReader::open_memory(stream, "x.gvid").value()->header_bytes());
  ASSERT_TRUE(decode_frame_packet(packet, info, 0).is_ok());
  const std::string payload = testing::packet_payload(packet);
  ASSERT_EQ(static_cast<uint8_t>(payload[0]),
            3 | format::kPayloadCompactSegments | format::kPayloadQuadraticIntra);
  const auto expect_rejected = [&](std::string p, const std::string& what) {
    auto r = decode_frame_packet(testing::with_payload(packet, std::move(p)), info, 0);
    ASSERT_FALSE(r.is_ok()) << what;
    EXPECT_NE(r.status().message().find(what), std::string::npos) << r.status().message();
  };
  std::string unknown = payload;
  unknown[0] = static_cast<char>(unknown[0] | 0x20);  // a P frame's merge bit
  expect_rejected(unknown, "merge outside a P frame");
  // Plane count, max transform, the deblocking bytes, then X's size as a varint: cut inside the
  // frame-level fields, then inside X's segment.
  expect_rejected(payload.substr(0, 5), "plane X: segment size exceeds the payload");
  expect_rejected(payload.substr(0, payload.size() / 3), "segment size exceeds the payload");
  // A varint longer than 10 bytes.
  expect_rejected(payload.substr(0, 4) + std::string(11, '\xff') + payload.substr(4),
                  "plane X: segment size exceeds the payload");
}

}  // namespace
}  // namespace gvkit::codec
