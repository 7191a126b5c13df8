// Format 2.0 and its profiles (docs/bitstream.md 1 and 1.2): the encoder writes 2.0 with the
// profile its options resolve to, every packet compact with compact segment sizes; a reader
// rejects unknown versions and profiles at open, and a packet that breaks its stream's profile or
// the 2.0 packet rules at decode, naming the file, the frame and the rule; legacy 1.x streams
// still open and say so. The CRC-32 that protects headers and packets is the standard one.
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/crc32.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "packet_surgery.hpp"

namespace gvkit::codec {
namespace {

using testing::make_stream;
using testing::stream_packets;
using testing::with_file_header_byte;

bool has(const Status& s, const std::string& text) {
  return s.message().find(text) != std::string::npos;
}

class StreamFormatTest : public ::testing::Test {
 protected:
  // An I P P stream (main), an intra-only lossy one and a lossless one, 32x32.
  void SetUp() override {
    frames_ = testing::make_moving_analytic_video(32, 3);
    info_ = testing::info_for(frames_);
    EncoderOptions o;
    o.preset = Preset::kFast;
    o.bframes = 0;
    main_ = encode_gvid(frames_, info_, o).value();
    o.intra_only = true;
    intra_ = encode_gvid(frames_, info_, o).value();
    o.intra_only = false;
    o.lossless = true;
    lossless_ = encode_gvid(frames_, info_, o).value();
  }
  size_t header_bytes(const std::string& stream) const {
    size_t n = 0;
    GVKIT_CHECK(format::read_file_header(stream, &n).is_ok());
    return n;
  }
  std::vector<GeometryImage> frames_;
  SequenceInfo info_;
  std::string main_, intra_, lossless_;
};

TEST_F(StreamFormatTest, EncoderWritesFormat20WithTheResolvedProfile) {
  const std::pair<const std::string*, Profile> cases[] = {
      {&main_, Profile::kMain}, {&intra_, Profile::kIntra}, {&lossless_, Profile::kLossless}};
  for (const auto& [stream, profile] : cases) {
    SCOPED_TRACE(profile_name(profile));
    EXPECT_EQ(stream->substr(0, 4), "GVID");
    EXPECT_EQ(static_cast<uint8_t>((*stream)[4]), 2);  // major
    EXPECT_EQ(static_cast<uint8_t>((*stream)[5]), 0);  // minor
    EXPECT_EQ(static_cast<uint8_t>((*stream)[6]), static_cast<uint8_t>(profile));
    EXPECT_EQ(static_cast<uint8_t>((*stream)[7]), 0);
    auto reader = GvidReader::open_memory(*stream, "x.gvid").value();
    EXPECT_FALSE(reader->format().legacy());
    EXPECT_EQ(reader->format().profile, profile);
    EXPECT_EQ(reader->format().description(), std::string("2.0, profile ") + profile_name(profile));
    // Every packet compact, with compact segment sizes.
    for (int64_t f = 0; f < reader->frame_count(); ++f) {
      EXPECT_TRUE(reader->packet_header(f).value().compact) << f;
      EXPECT_TRUE(reader->decode_frame(f).is_ok()) << f;
    }
    for (const auto& [type, flags] : testing::payload_flags(*stream))
      EXPECT_TRUE(flags & format::kPayloadCompactSegments);
  }
}

TEST(StreamFormat, OptionsResolveTheirProfile) {
  EncoderOptions o;
  EXPECT_EQ(o.resolved_profile(), Profile::kMain);
  o.intra_period = 1;
  EXPECT_EQ(o.resolved_profile(), Profile::kIntra);
  o.max_error_mm = 0.1;  // near-lossless is transform bypass too
  EXPECT_EQ(o.resolved_profile(), Profile::kLossless);
  o.profile = Profile::kMain;  // a chosen profile stays
  EXPECT_EQ(o.resolved_profile(), Profile::kMain);
  // A profile implies its constraints: every frame intra, every frame transform bypass.
  EncoderOptions intra;
  intra.profile = Profile::kIntra;
  EXPECT_TRUE(intra.is_intra(7));
  EncoderOptions lossless;
  lossless.profile = Profile::kLossless;
  EXPECT_TRUE(lossless.bypass());
  // ... and rejects what contradicts them, by name.
  intra.bframes = 2;
  EXPECT_NE(intra.check().message().find("profile intra"), std::string::npos);
  lossless.bitrate_kbps = 100;
  EXPECT_NE(lossless.check().message().find("profile lossless"), std::string::npos);
  EXPECT_EQ(parse_profile("intra").value(), Profile::kIntra);
  EXPECT_NE(parse_profile("high").status().message().find("'high'"), std::string::npos);
}

TEST_F(StreamFormatTest, ChosenProfilesConstrainTheFrames) {
  EncoderOptions o;
  o.preset = Preset::kFast;
  o.profile = Profile::kIntra;
  auto intra = GvidReader::open_memory(encode_gvid(frames_, info_, o).value(), "i.gvid").value();
  EXPECT_EQ(intra->format().profile, Profile::kIntra);
  for (int64_t f = 0; f < intra->frame_count(); ++f)
    EXPECT_EQ(intra->frame_type(f), format::FrameType::kIntra) << f;
  o.profile = Profile::kLossless;
  const std::string stream = encode_gvid(frames_, info_, o).value();
  auto lossless = GvidReader::open_memory(stream, "l.gvid").value();
  EXPECT_EQ(lossless->format().profile, Profile::kLossless);
  const auto planes = quantize_geometry(frames_[2], info_);
  const auto decoded = quantize_geometry(lossless->decode_frame(2).value(), info_);
  for (int p = 0; p < 3; ++p)
    EXPECT_EQ(decoded[p].samples, planes[p].samples) << "plane " << p;  // exact
}

TEST_F(StreamFormatTest, UnknownVersionsAndProfilesAreUnsupportedAtOpen) {
  const struct {
    size_t offset;
    uint8_t value;
    const char* message;
  } cases[] = {
      {4, 3, "version 3.0"},   {5, 1, "version 2.1"},       {6, 0, "profile_idc 0"},
      {6, 4, "profile_idc 4"}, {6, 255, "profile_idc 255"}, {7, 1, "byte 7 is 1"},
  };
  for (const auto& c : cases) {
    const std::string bad = with_file_header_byte(main_, c.offset, c.value);
    auto reader = GvidReader::open_memory(bad, "x.gvid");
    ASSERT_FALSE(reader.is_ok()) << c.message;
    EXPECT_EQ(reader.status().code(), StatusCode::kUnsupported) << c.message;
    EXPECT_TRUE(has(reader.status(), "x.gvid: header: ")) << reader.status().message();
    EXPECT_TRUE(has(reader.status(), c.message)) << reader.status().message();
  }
  // 1.15 was never written.
  std::string v115 = with_file_header_byte(main_, 4, 1);
  v115 = with_file_header_byte(v115, 5, 15);
  auto reader = GvidReader::open_memory(v115, "x.gvid");
  ASSERT_FALSE(reader.is_ok());
  EXPECT_TRUE(has(reader.status(), "version 1.15")) << reader.status().message();
}

TEST_F(StreamFormatTest, PacketsThatBreakTheProfileFailNamingTheFrameAndTheRule) {
  // The I P P stream relabelled intra: frames 1 and 2 are P frames.
  auto as_intra =
      GvidReader::open_memory(with_file_header_byte(main_, 6, 2), "main-as-intra.gvid").value();
  EXPECT_TRUE(as_intra->decode_frame(0).is_ok());
  auto p = as_intra->decode_frame(1);
  ASSERT_FALSE(p.is_ok());
  EXPECT_EQ(p.status().code(), StatusCode::kCorruptData);
  EXPECT_TRUE(has(p.status(), "main-as-intra.gvid: frame 1"));
  EXPECT_TRUE(has(p.status(), "profile intra: a P frame")) << p.status().message();
  // The lossy intra stream relabelled lossless: every frame is lossy.
  auto as_lossless =
      GvidReader::open_memory(with_file_header_byte(intra_, 6, 1), "intra-as-lossless.gvid")
          .value();
  for (int64_t f = 0; f < as_lossless->frame_count(); ++f) {
    auto frame = as_lossless->decode_frame(f);
    ASSERT_FALSE(frame.is_ok());
    EXPECT_TRUE(has(frame.status(), "frame " + std::to_string(f) + ": profile lossless: a lossy"))
        << frame.status().message();
  }
  // Relabelled main, both decode: main allows everything.
  for (const std::string* s : {&intra_, &lossless_}) {
    auto reader = GvidReader::open_memory(with_file_header_byte(*s, 6, 3), "x.gvid").value();
    for (int64_t f = 0; f < reader->frame_count(); ++f)
      EXPECT_TRUE(reader->decode_frame(f).is_ok()) << f;
  }
}

TEST_F(StreamFormatTest, LegacyPacketSyntaxIsRejectedInA20Stream) {
  const std::string header = main_.substr(0, header_bytes(main_));
  std::vector<std::string> packets = stream_packets(main_);
  // Frame 1 with the full 24-byte header (`GVFR`).
  std::vector<std::string> full = packets;
  auto h = format::read_packet_header(full[1]).value();
  const std::string payload = testing::packet_payload(full[1]);
  h.compact = false;
  full[1] = format::write_packet_header(h) + payload;
  auto reader = GvidReader::open_memory(make_stream(header, full), "full.gvid").value();
  EXPECT_TRUE(reader->decode_frame(0).is_ok());
  auto frame = reader->decode_frame(1);
  ASSERT_FALSE(frame.is_ok());
  EXPECT_TRUE(
      has(frame.status(), "full.gvid: frame 1: full packet header ('GVFR') in a format 2.0"))
      << frame.status().message();
  // Frame 0 with the compact-sizes bit of its payload cleared (CRC fixed).
  std::vector<std::string> u32 = packets;
  std::string p0 = testing::packet_payload(u32[0]);
  p0[0] = static_cast<char>(p0[0] & ~format::kPayloadCompactSegments);
  u32[0] = testing::with_payload(u32[0], p0);
  reader = GvidReader::open_memory(make_stream(header, u32), "u32.gvid").value();
  frame = reader->decode_frame(0);
  ASSERT_FALSE(frame.is_ok());
  EXPECT_TRUE(has(frame.status(), "u32.gvid: frame 0: payload flags: u32 segment sizes"))
      << frame.status().message();
  // A damaged payload is still reported as damage, not as a rule broken.
  std::string bad = packets[0];
  bad[bad.size() - 3] ^= 0x10;
  std::vector<std::string> damaged = packets;
  damaged[0] = bad;
  reader = GvidReader::open_memory(make_stream(header, damaged), "crc.gvid").value();
  frame = reader->decode_frame(0);
  ASSERT_FALSE(frame.is_ok());
  EXPECT_TRUE(has(frame.status(), "payload CRC mismatch")) << frame.status().message();
}

TEST(StreamFormat, LegacyStreamsOpenAndSayTheirVersion) {
  auto reader = GvidReader::open(std::filesystem::path(GVKIT_GOLDEN_DIR) / "v1" /
                                 "analytic_temporal_slow_qp6_ibpbp_v1_9_48.gvid");
  ASSERT_TRUE(reader.is_ok()) << reader.status().message();
  EXPECT_TRUE((*reader)->format().legacy());
  EXPECT_EQ((*reader)->format().minor, 9);
  EXPECT_EQ((*reader)->format().description(), "1.9 (legacy, read-only)");
  EXPECT_FALSE((*reader)->packet_header(0).value().compact);  // 1.9: full packet headers
  for (int64_t f = 0; f < (*reader)->frame_count(); ++f)
    EXPECT_TRUE((*reader)->decode_frame(f).is_ok()) << f;
}

// The check value of CRC-32/ISO-HDLC, chaining, and a long buffer against the bytewise
// definition (reflected polynomial 0xEDB88320, initial and final value inverted).
TEST(Crc32, IsTheStandardCrc32) {
  EXPECT_EQ(crc32(std::string_view("123456789")), 0xCBF43926u);
  EXPECT_EQ(crc32(std::string_view()), 0u);
  std::mt19937 rng(1);
  std::string bytes(3 << 20, '\0');
  for (char& b : bytes) b = static_cast<char>(rng());
  uint32_t plain = ~0u;
  for (const char b : bytes) {
    plain ^= static_cast<uint8_t>(b);
    for (int k = 0; k < 8; ++k) plain = (plain & 1) ? 0xEDB88320u ^ (plain >> 1) : plain >> 1;
  }
  EXPECT_EQ(crc32(bytes), ~plain);
  const std::string_view all(bytes);
  EXPECT_EQ(crc32(all.data() + 1000, all.size() - 1000, crc32(all.substr(0, 1000))), crc32(all));
}

}  // namespace
}  // namespace gvkit::codec
