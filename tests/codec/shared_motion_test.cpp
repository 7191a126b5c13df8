// Shared motion (flags2 bit 0: the Y and Z planes take over the X plane's vector per macroblock
// with one flag) and inter decimation (encoder only). The decoder reproduces the encoder's
// reconstruction exactly in every configuration; threads do not change the bytes; the Y and Z
// planes spend fewer motion bits than X; packets with unknown or misplaced flags2 bits, or
// truncated, are rejected with a message; off, no packet has the flag.
#include <string>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/byte_io.hpp"
#include "gvkit/codec/crc32.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/gvid_writer.hpp"

namespace gvkit::codec {
namespace {

struct Coded {
  std::vector<std::string> packets;
  std::vector<std::vector<SamplePlane>> recon;  // the encoder's reconstructed planes
  std::vector<FrameCodingStats> stats;
};

// The analytic surface moving by (0.75, 0.375) pixels per frame: real motion in the picture.
std::vector<GeometryImage> video(int size, int frames) {
  testing::GeometryVideoOptions o;
  o.size = size;
  o.frames = frames;
  auto video = testing::make_analytic_video(o);
  testing::move_in_picture(&video, 0.75);
  return video;
}

SequenceInfo info_for(const std::vector<GeometryImage>& frames) {
  auto info = make_sequence_info(frames, 16, 30.0);
  GVKIT_CHECK(info.is_ok(), info.status().message());
  return std::move(info).value();
}

Coded encode(const std::vector<GeometryImage>& frames, const SequenceInfo& info,
             const EncoderOptions& o) {
  Coded c;
  std::vector<SamplePlane> reference;
  for (size_t i = 0; i < frames.size(); ++i) {
    auto e = encode_frame(frames[i], info, o, static_cast<uint32_t>(i),
                          o.is_intra(static_cast<int64_t>(i)) ? nullptr : &reference);
    GVKIT_CHECK(e.is_ok(), e.status().message());
    c.packets.push_back(e->packet);
    c.recon.push_back(e->planes);
    c.stats.push_back({o.is_intra(static_cast<int64_t>(i)), e->plane_stats});
    reference = e->planes;
  }
  return c;
}

// Decodes every packet in turn; expects each frame's planes to equal the encoder's.
void expect_decoder_matches(const Coded& c, const SequenceInfo& info, const std::string& what) {
  std::vector<SamplePlane> reference;
  for (size_t i = 0; i < c.packets.size(); ++i) {
    std::vector<SamplePlane> planes;
    const bool intra = format::read_packet_header(c.packets[i])->type == format::FrameType::kIntra;
    auto image = decode_frame_packet(c.packets[i], info, static_cast<int64_t>(i),
                                     intra ? nullptr : &reference, &planes);
    ASSERT_TRUE(image.is_ok()) << what << " frame " << i << ": " << image.status().message();
    ASSERT_EQ(planes.size(), c.recon[i].size());
    for (size_t p = 0; p < planes.size(); ++p)
      ASSERT_EQ(planes[p].samples, c.recon[i][p].samples)
          << what << " frame " << i << " plane " << p;
    reference = std::move(planes);
  }
}

// A packet with its header replaced (CRC recomputed), payload unchanged.
std::string with_header(const std::string& packet, const format::PacketHeader& header) {
  const auto old = format::read_packet_header(packet);
  GVKIT_CHECK(old.is_ok());
  return format::write_packet_header(header) + packet.substr(old->header_size);
}

TEST(SharedMotion, DecoderReproducesTheEncoderInEveryConfiguration) {
  const auto frames = video(48, 4);
  const SequenceInfo info = info_for(frames);
  for (Preset preset : {Preset::kFast, Preset::kSlow})
    for (int mode = 0; mode < 3; ++mode)  // lossy, lossless, near-lossless
      for (bool shared : {false, true})
        for (bool decimation : {false, true}) {
          EncoderOptions o;
          o.cross_plane = false;  // shared motion's syntax alone
          o.preset = preset;
          o.qp = 0;
          o.intra_period = 4;
          o.lossless = mode == 1;
          o.max_error_mm = mode == 2 ? 0.05 : 0;
          if (mode) o.qp = 12;
          o.shared_motion = shared;
          o.inter_decimation = decimation;
          o.skip_check = decimation;  // the predicted-vector skip check with it
          const std::string what = std::string(preset_name(preset)) + " mode " +
                                   std::to_string(mode) + " shared " + std::to_string(shared) +
                                   " decimation " + std::to_string(decimation);
          const Coded c = encode(frames, info, o);
          expect_decoder_matches(c, info, what);
          for (size_t i = 0; i < c.packets.size(); ++i) {
            const auto header = format::read_packet_header(c.packets[i]);
            ASSERT_TRUE(header.is_ok());
            EXPECT_EQ(header->flags2 & format::kFrame2SharedMotion,
                      shared && i > 0 ? format::kFrame2SharedMotion : 0)
                << what;
          }
        }
}

TEST(SharedMotion, ThreadsWriteTheSameBytesAndYZSpendFewerMotionBits) {
  const auto frames = video(64, 3);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.cross_plane = false;  // shared motion's syntax alone
  o.preset = Preset::kFast;
  o.qp = -6;
  o.shared_motion = true;
  o.bframes = 0;  // shared motion is a P-frame tool
  o.refs = 1;     // one reference: the motion bits are vectors only (no ref_idx)
  // Fixed rounding offsets: with RDO quantization the Z plane of this
  // small video takes its own vector a little more often (motion bits 172 against X's 170).
  o.rdoq = false;
  std::string one;
  for (int threads : {1, 3}) {
    o.threads = threads;
    std::vector<FrameCodingStats> stats;
    auto bytes = encode_gvid(frames, info, o, &stats);
    ASSERT_TRUE(bytes.is_ok()) << bytes.status().message();
    if (threads == 1) {
      one = *bytes;
      double motion[3] = {};
      for (const auto& f : stats)
        for (int p = 0; p < 3; ++p) motion[p] += f.planes[p].bits[kSyntaxMotion];
      EXPECT_GT(motion[0], 0.0);
      EXPECT_LT(motion[1], motion[0]);
      EXPECT_LT(motion[2], motion[0]);
    } else {
      EXPECT_EQ(*bytes, one);
    }
  }
}

TEST(SharedMotion, BadFlagsAndTruncatedPacketsAreRejected) {
  const auto frames = video(48, 2);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.preset = Preset::kFast;
  o.qp = 0;
  o.shared_motion = true;
  // flags2 = shared motion only, no payload field before the segments.
  o.max_transform = 4;
  o.cross_plane = false;
  o.cross_plane_contexts = false;
  o.temporal_contexts = false;
  o.deblocking = false;
  o.resolution = Resolution::kFull;
  const Coded c = encode(frames, info, o);
  auto header = format::read_packet_header(c.packets[1]);
  ASSERT_TRUE(header.is_ok());
  ASSERT_EQ(header->flags2, format::kFrame2SharedMotion);
  const auto expect_error = [&](const std::string& packet, const std::vector<SamplePlane>* ref,
                                const std::string& message) {
    auto r = decode_frame_packet(packet, info, 1, ref);
    ASSERT_FALSE(r.is_ok()) << message;
    EXPECT_NE(r.status().message().find(message), std::string::npos) << r.status().message();
  };
  // Flags2 bit 7 (temporal contexts) in the intra frame.
  auto temporal = format::read_packet_header(c.packets[0]);
  ASSERT_TRUE(temporal.is_ok());
  temporal->flags2 = format::kFrame2TemporalContexts;
  expect_error(with_header(c.packets[0], *temporal), nullptr,
               "temporal contexts in an intra frame");
  auto intra = format::read_packet_header(c.packets[0]);
  ASSERT_TRUE(intra.is_ok());
  intra->flags2 = format::kFrame2SharedMotion;
  expect_error(with_header(c.packets[0], *intra), nullptr, "shared motion in an intra frame");
  // Truncated payload: the header's size no longer fits.
  expect_error(c.packets[1].substr(0, c.packets[1].size() - 5), &c.recon[0], "truncated");
  // A truncated segment with a consistent header: the CABAC data ends early or is inconsistent.
  // The payload: its first byte, then X's size (varint) and segment, Y's likewise, then Z.
  std::string payload = c.packets[1].substr(format::read_packet_header(c.packets[1])->header_size);
  ByteReader in(std::string_view(payload).substr(1));
  const std::string_view x = in.bytes(in.varint());
  const std::string_view y = in.bytes(in.varint());
  const std::string_view z = in.bytes(in.remaining());
  ASSERT_TRUE(in.ok());
  ASSERT_GT(y.size(), 4u);
  ByteWriter out;
  out.u8(static_cast<uint8_t>(payload[0]));
  out.varint(x.size());
  out.bytes(x);
  out.varint(y.size() / 2);
  out.bytes(y.substr(0, y.size() / 2));
  out.bytes(z);
  const std::string cut = out.take();
  format::PacketHeader h = *header;
  h.payload_size = static_cast<uint32_t>(cut.size());
  h.payload_crc = crc32(cut);
  auto r = decode_frame_packet(format::write_packet_header(h) + cut, info, 1, &c.recon[0]);
  ASSERT_FALSE(r.is_ok());
  EXPECT_NE(r.status().message().find("plane Y"), std::string::npos) << r.status().message();
}

TEST(SharedMotion, OffCodesNoSharedMotionFlag) {
  const auto frames = video(48, 2);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.preset = Preset::kFast;
  o.qp = 0;
  o.shared_motion = false;
  o.inter_decimation = false;
  const Coded c = encode(frames, info, o);
  for (const std::string& packet : c.packets)
    EXPECT_EQ(format::read_packet_header(packet)->flags2 & format::kFrame2SharedMotion, 0);
  EncoderOptions d = o;
  d.inter_decimation = true;
  const Coded dc = encode(frames, info, d);
  EXPECT_EQ(dc.packets[0], c.packets[0]);  // decimation touches inter residuals only
  expect_decoder_matches(dc, info, "decimation");
}

}  // namespace
}  // namespace gvkit::codec
