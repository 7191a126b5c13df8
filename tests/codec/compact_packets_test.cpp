// Compact packets (docs/bitstream.md 2; every format 2.0 packet): the compact packet header
// round-trips and rejects every damaged byte, streams with and without texture round-trip in
// every frame type and coding mode with compact headers of at most 15 bytes, and a stream
// without its index is rebuilt by a scan that still finds a compact packet with a damaged
// payload (which then fails naming the frame) and loses only a packet whose header is damaged.
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/crc8.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"

namespace gvkit::codec {
namespace {

TEST(CompactPackets, Crc8IsTheSmbusCrc) {
  EXPECT_EQ(crc8("123456789"), 0xF4);  // the catalogue's check value
  EXPECT_EQ(crc8(""), 0x00);
}

TEST(CompactPackets, HeaderRoundTripsAndRejectsEveryDamagedByte) {
  for (const uint32_t number : {0u, 127u, 128u, 300000u, 0xFFFFFFFFu})
    for (const uint32_t size : {0u, 5u, 16384u, 0xFFFFFFFFu}) {
      format::PacketHeader h;
      h.compact = true;
      h.type = format::FrameType::kBidirectional;
      h.flags = 0xA5;
      h.flags2 = 0x5A;
      h.qp = -17;
      h.frame_number = number;
      h.payload_size = size;
      h.payload_crc = 0xDEADBEEF;
      const std::string bytes = format::write_packet_header(h);
      ASSERT_GE(bytes.size(), format::kCompactPacketHeaderMinSize);
      ASSERT_LE(bytes.size(), format::kCompactPacketHeaderMaxSize);
      // Followed by payload bytes: the header knows its own end.
      auto read = format::read_packet_header(bytes + "payload");
      ASSERT_TRUE(read.is_ok()) << read.status().message();
      EXPECT_TRUE(read->compact);
      EXPECT_EQ(read->header_size, bytes.size());
      EXPECT_EQ(read->type, h.type);
      EXPECT_EQ(read->flags, h.flags);
      EXPECT_EQ(read->flags2, h.flags2);
      EXPECT_EQ(read->qp, h.qp);
      EXPECT_EQ(read->frame_number, number);
      EXPECT_EQ(read->payload_size, size);
      EXPECT_EQ(read->payload_crc, h.payload_crc);
      for (size_t i = 0; i < bytes.size(); ++i)
        for (int bit = 0; bit < 8; ++bit) {
          std::string bad = bytes;
          bad[i] = static_cast<char>(bad[i] ^ (1 << bit));
          EXPECT_FALSE(format::read_packet_header(bad + "payload").is_ok())
              << "byte " << i << " bit " << bit;
        }
      for (size_t len = 0; len < bytes.size(); ++len)
        EXPECT_FALSE(format::read_packet_header(bytes.substr(0, len)).is_ok()) << len;
    }
}

TEST(CompactPackets, StreamsRoundTripWithShortHeadersInEveryMode) {
  auto frames = testing::make_moving_analytic_video(48, 7);
  for (const bool texture : {false, true}) {
    if (texture)
      for (GeometryImage& f : frames) f.texture = cv::Mat(48, 48, CV_32F, cv::Scalar(0.35));
    const SequenceInfo info = testing::info_for(frames);
    for (int mode = 0; mode < 4; ++mode) {  // fast QP 12, slow QP 0, lossless, near-lossless
      SCOPED_TRACE(std::string(texture ? "texture" : "xyz") + " mode " + std::to_string(mode));
      EncoderOptions o;
      o.preset = mode == 1 ? Preset::kSlow : Preset::kFast;
      o.qp = mode == 0 ? 12 : 0;
      o.lossless = mode == 2;
      o.max_error_mm = mode == 3 ? 0.05 : 0;
      o.intra_period = 5;  // I P B P B I P ...
      const std::string stream = testing::writer_round_trip(frames, info, o);
      auto reader = GvidReader::open_memory(stream, "x.gvid").value();
      for (int64_t f = 0; f < reader->frame_count(); ++f) {
        const auto h = reader->packet_header(f).value();
        EXPECT_TRUE(h.compact);
        // Frame numbers below 128 and payloads below 16 KB: 2 + 4 + 1 + 2 + 4 + 1 bytes.
        EXPECT_LE(h.header_size, 15u) << "frame " << f;
      }
    }
  }
}

class CompactScan : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto frames = testing::make_moving_analytic_video(48, 4);
    EncoderOptions o;
    o.qp = 6;
    o.bframes = 0;
    o.intra_period = 2;  // I P I P: a lost frame costs at most its P frame
    stream_ = encode_gvid(frames, testing::info_for(frames), o).value();
    auto reader = GvidReader::open_memory(stream_, "x.gvid").value();
    for (int64_t f = 0; f < reader->frame_count(); ++f) {
      offsets_.push_back(static_cast<size_t>(reader->header_bytes()));
      for (int64_t g = 0; g < f; ++g) offsets_.back() += reader->frame_bits(g) / 8;
    }
    // Without the index and trailer: the reader must scan.
    const size_t index_at = offsets_.back() + reader->frame_bits(3) / 8;
    stream_.resize(index_at);
  }
  std::string stream_;
  std::vector<size_t> offsets_;  // of each packet (I P I P: stream order is display order)
};

TEST_F(CompactScan, FindsEveryPacketWithoutTheIndex) {
  auto reader = GvidReader::open_memory(stream_, "x.gvid").value();
  EXPECT_TRUE(reader->index_rebuilt());
  ASSERT_EQ(reader->frame_count(), 4);
  for (int64_t f = 0; f < 4; ++f) EXPECT_TRUE(reader->decode_frame(f).is_ok()) << f;
}

TEST_F(CompactScan, DamagedPayloadIsFoundAndNamesItsFrame) {
  for (const int frame : {1, 3}) {  // in the middle and the last packet
    std::string bad = stream_;
    const auto header = format::read_packet_header(std::string_view(bad).substr(offsets_[frame]));
    ASSERT_TRUE(header.is_ok());
    bad[offsets_[frame] + header->header_size + header->payload_size / 2] ^= 0x08;
    auto reader = GvidReader::open_memory(bad, "x.gvid").value();
    ASSERT_EQ(reader->frame_count(), 4) << frame;
    auto damaged = reader->decode_frame(frame);
    ASSERT_FALSE(damaged.is_ok());
    EXPECT_NE(damaged.status().message().find("x.gvid: frame " + std::to_string(frame) +
                                              ": payload CRC mismatch"),
              std::string::npos)
        << damaged.status().message();
    for (int64_t f = 0; f < 4; ++f) {
      if (f != frame) {
        EXPECT_TRUE(reader->decode_frame(f).is_ok()) << f;
      }
    }
  }
}

TEST_F(CompactScan, DamagedHeaderLosesThatPacketOnly) {
  std::string bad = stream_;
  bad[offsets_[2] + 6] ^= 0x01;  // frame 2's frame number: the header's CRC-8 fails
  auto reader = GvidReader::open_memory(bad, "x.gvid").value();
  ASSERT_EQ(reader->frame_count(), 3);
  EXPECT_TRUE(reader->decode_frame(0).is_ok());
  EXPECT_TRUE(reader->decode_frame(1).is_ok());
  // Frame 3 (a P frame) lost its reference, and says so.
  auto orphan = reader->decode_frame(2);
  ASSERT_FALSE(orphan.is_ok());
  EXPECT_NE(orphan.status().message().find("missing"), std::string::npos)
      << orphan.status().message();
}

}  // namespace
}  // namespace gvkit::codec
