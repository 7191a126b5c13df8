// B frames (frame type 2): the encoder's reconstruction equals the decoder's output bit for bit
// (lossy and lossless, both presets, 1..3 B frames), lossless B frames are exact, random access
// in any order gives the sequential frames, trailing B-frame candidates become P frames, a
// damaged anchor fails the frames that depend on it (naming it) while the rest decode, bad B
// syntax is rejected with a message, and bframes 0 (or intra only) writes no B frame.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <numeric>
#include <random>
#include <utility>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/byte_io.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/core/atomic_file.hpp"
#include "packet_surgery.hpp"
#include "support/test_support.hpp"

namespace gvkit::codec {
namespace {
using format::FrameType;

// The analytic surface moving by (shift, shift / 2) pixels per frame (so that the motion
// search has work to do).
std::vector<GeometryImage> moving_video(int size, int frames, double shift = 0.75) {
  testing::GeometryVideoOptions o;
  o.size = size;
  o.frames = frames;
  auto video = testing::make_analytic_video(o);
  testing::move_in_picture(&video, shift);
  return video;
}

SequenceInfo info_for(const std::vector<GeometryImage>& frames, int bit_depth = 16) {
  auto info = make_sequence_info(frames, bit_depth, 30.0);
  GVKIT_CHECK(info.is_ok(), info.status().message());
  return std::move(info).value();
}

std::unique_ptr<GvidReader> open_bytes(std::string bytes) {
  auto reader = GvidReader::open_memory(std::move(bytes), "b.gvid");
  if (!reader.is_ok()) ADD_FAILURE() << reader.status().message();
  return reader.is_ok() ? std::move(reader).value() : nullptr;
}

bool same_samples(const GeometryImage& a, const GeometryImage& b) {
  if (a.xyz_mm.size() != b.xyz_mm.size() || a.xyz_mm.type() != b.xyz_mm.type()) return false;
  for (int y = 0; y < a.xyz_mm.rows; ++y)
    if (std::memcmp(a.xyz_mm.ptr(y), b.xyz_mm.ptr(y), a.xyz_mm.cols * a.xyz_mm.elemSize()) != 0)
      return false;
  return true;
}

std::string types_of(GvidReader& reader) {
  std::string s;
  for (int64_t i = 0; i < reader.frame_count(); ++i) s += frame_type_name(reader.frame_type(i));
  return s;
}

// The packet of frame `display` (header + payload) and its offset in the stream.
std::string_view packet_of(const std::string& bytes, GvidReader& reader, int64_t display,
                           size_t* offset) {
  // The packets follow the header in decode order.
  size_t pos = static_cast<size_t>(reader.header_bytes());
  for (int64_t k = 0;; ++k) {
    auto h = format::read_packet_header(std::string_view(bytes).substr(pos));
    GVKIT_CHECK(h.is_ok());
    if (static_cast<int64_t>(h->frame_number) == display) {
      *offset = pos;
      return std::string_view(bytes).substr(pos, h->header_size + h->payload_size);
    }
    pos += h->header_size + h->payload_size;
  }
}

// Largest point error (mm) over the domain.
double max_error(const GeometryImage& a, const GeometryImage& b) {
  double worst = 0;
  for (int y = 0; y < a.xyz_mm.rows; ++y)
    for (int x = 0; x < a.xyz_mm.cols; ++x)
      if (a.domain_mask.at<uint8_t>(y, x))
        worst =
            std::max(worst, cv::norm(a.xyz_mm.at<cv::Vec3f>(y, x) - b.xyz_mm.at<cv::Vec3f>(y, x)));
  return worst;
}

TEST(BFrames, EncoderReconstructionEqualsDecoderOutputBitExactly) {
  const auto frames = moving_video(32, 7);
  const SequenceInfo info = info_for(frames);
  testing::TempDir dir;
  // The worst point error of the same video without B frames, per preset (the lossy bound).
  double p_worst[2] = {0, 0};
  for (const Preset preset : {Preset::kFast, Preset::kSlow}) {
    EncoderOptions o;
    o.qp = 4;
    o.preset = preset;
    auto reader = open_bytes(encode_gvid(frames, info, o).value());
    ASSERT_TRUE(reader);
    for (int f = 0; f < 7; ++f)
      p_worst[preset == Preset::kSlow] = std::max(
          p_worst[preset == Preset::kSlow], max_error(frames[f], reader->decode_frame(f).value()));
  }
  for (int bframes = 1; bframes <= 3; ++bframes)
    for (const bool lossless : {false, true})
      for (const Preset preset : {Preset::kFast, Preset::kSlow}) {
        SCOPED_TRACE("bframes " + std::to_string(bframes) + (lossless ? " lossless " : " qp 4 ") +
                     preset_name(preset));
        EncoderOptions o;
        o.bframes = bframes;
        o.lossless = lossless;
        o.qp = 4;
        o.preset = preset;
        const auto path = dir / "b.gvid";
        std::vector<GeometryImage> recon;
        {
          auto writer = GvidWriter::create(path, info, o);
          ASSERT_TRUE(writer.is_ok()) << writer.status().message();
          for (const auto& f : frames) {
            auto done = (*writer)->write(f);
            ASSERT_TRUE(done.is_ok()) << done.status().message();
            for (auto& r : *done) recon.push_back(std::move(r));
          }
          auto rest = (*writer)->finish();
          ASSERT_TRUE(rest.is_ok()) << rest.status().message();
          for (auto& r : *rest) recon.push_back(std::move(r));
          EXPECT_EQ((*writer)->frame_types()[1], FrameType::kBidirectional);
        }
        ASSERT_EQ(recon.size(), frames.size());
        auto bytes = read_file(path);
        ASSERT_TRUE(bytes.is_ok());
        // The same stream from encode_gvid.
        auto in_memory = encode_gvid(frames, info, o);
        ASSERT_TRUE(in_memory.is_ok());
        EXPECT_EQ(*in_memory, *bytes);
        auto reader = open_bytes(*bytes);
        ASSERT_TRUE(reader);
        ASSERT_EQ(reader->frame_count(), 7);
        // Anchors every bframes + 1 frames; the frames after the last anchor are P frames.
        std::string expected;
        for (int f = 0; f < 7; ++f) {
          const int last_anchor = 6 / (bframes + 1) * (bframes + 1);
          expected += f == 0 ? 'I' : (f % (bframes + 1) == 0 || f > last_anchor ? 'P' : 'B');
        }
        EXPECT_EQ(types_of(*reader), expected);
        for (int f = 0; f < 7; ++f) {
          auto decoded = reader->decode_frame(f);
          ASSERT_TRUE(decoded.is_ok()) << decoded.status().message();
          EXPECT_EQ(decoded->index, f);
          EXPECT_TRUE(same_samples(*decoded, recon[f])) << "frame " << f;
          if (lossless) {
            const GeometryImage exact =
                dequantize_geometry(quantize_geometry(frames[f], info), info, f);
            EXPECT_TRUE(same_samples(*decoded, exact)) << "lossless frame " << f;
          } else {
            // Lossy: B frames are coded 2 QP coarser (1.26x the step) than the P frames; their
            // worst error stays within twice the worst of the stream without B frames.
            EXPECT_LT(max_error(frames[f], *decoded), 2.0 * p_worst[preset == Preset::kSlow])
                << "frame " << f;
          }
        }
      }
}

TEST(BFrames, PacketsAreInDecodeOrderAndBFramesAreCheaper) {
  const auto frames = moving_video(48, 5, 0.5);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.bframes = 1;
  o.qp = 4;
  o.preset = Preset::kFast;
  std::vector<FrameCodingStats> stats;
  auto bytes = encode_gvid(frames, info, o, &stats);
  ASSERT_TRUE(bytes.is_ok());
  auto reader = open_bytes(*bytes);
  ASSERT_TRUE(reader);
  EXPECT_EQ(types_of(*reader), "IBPBP");
  // Decode order: I0 P2 B1 P4 B3.
  const int64_t position[5] = {0, 2, 1, 4, 3};
  for (int f = 0; f < 5; ++f) EXPECT_EQ(reader->decode_position(f), position[f]) << f;
  ASSERT_EQ(stats.size(), 5u);
  EXPECT_TRUE(stats[1].bidirectional && stats[3].bidirectional);
  EXPECT_FALSE(stats[2].bidirectional || stats[2].intra);
  // A B frame (coarser, predicted from both sides) costs less than the P frames around it.
  EXPECT_LT(reader->frame_bits(1), reader->frame_bits(2));
  EXPECT_LT(reader->frame_bits(3), reader->frame_bits(4));
  int64_t b_skip = 0, b_mbs = 0;
  for (const int f : {1, 3})
    for (const auto& p : stats[f].planes) {
      b_skip += p.skip_mbs;
      b_mbs += p.skip_mbs + p.inter_mbs + p.intra_mbs + p.td_mbs;
    }
  EXPECT_EQ(b_mbs, 2 * 3 * 9);
  EXPECT_GT(b_skip, 0);
}

TEST(BFrames, RandomAccessInAnyOrderGivesTheSequentialFrames) {
  // GOPs of 5 frames with 2 B frames: I B B P B | I B B P; frame 4 is a B frame between the P
  // frame 3 and the next GOP's I frame 5.
  const auto frames = moving_video(32, 9);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.bframes = 2;
  o.intra_period = 5;
  o.qp = 2;
  o.preset = Preset::kFast;
  auto bytes = encode_gvid(frames, info, o);
  ASSERT_TRUE(bytes.is_ok());
  auto sequential = open_bytes(*bytes);
  ASSERT_TRUE(sequential);
  EXPECT_EQ(types_of(*sequential), "IBBPBIBBP");
  std::vector<GeometryImage> expected;
  for (int f = 0; f < 9; ++f) {
    auto frame = sequential->decode_frame(f);
    ASSERT_TRUE(frame.is_ok()) << frame.status().message();
    expected.push_back(std::move(frame).value());
  }
  std::mt19937 rng(7);
  for (int round = 0; round < 4; ++round) {
    auto reader = open_bytes(*bytes);
    ASSERT_TRUE(reader);
    std::vector<int> order(9);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    if (round == 0) std::reverse(order.begin(), order.end());
    for (int i = 0; i < 12; ++i) {
      const int f = i < 9 ? order[i] : order[i % 3];  // and some again
      auto frame = reader->decode_frame(f);
      ASSERT_TRUE(frame.is_ok()) << frame.status().message();
      EXPECT_TRUE(same_samples(*frame, expected[f])) << "round " << round << " frame " << f;
      EXPECT_EQ(frame->index, f);
    }
  }
}

// The reader writes a frame into the buffers of the frame it returned last only when its caller
// has let that one go: a frame still held is never written over.
TEST(BFrames, TheReaderReusesOnlyTheBuffersOfFramesItsCallerReleased) {
  const auto frames = moving_video(32, 5);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.preset = Preset::kFast;
  o.intra_period = 5;
  auto bytes = encode_gvid(frames, info, o);
  ASSERT_TRUE(bytes.is_ok());
  std::vector<GeometryImage> expected;
  {
    auto fresh = open_bytes(*bytes);
    ASSERT_TRUE(fresh);
    for (int f = 0; f < 5; ++f) {
      auto frame = fresh->decode_frame(f);
      ASSERT_TRUE(frame.is_ok()) << frame.status().message();
      GeometryImage copy = *frame;
      copy.xyz_mm = frame->xyz_mm.clone();
      expected.push_back(std::move(copy));
    }
  }
  auto reader = open_bytes(*bytes);
  ASSERT_TRUE(reader);
  auto held = reader->decode_frame(0);
  ASSERT_TRUE(held.is_ok());
  const uchar* held_data = held->xyz_mm.data;
  const uchar* released_data = nullptr;
  {
    auto next = reader->decode_frame(1);  // frame 0 is still held: new buffers
    ASSERT_TRUE(next.is_ok());
    EXPECT_NE(next->xyz_mm.data, held_data);
    EXPECT_TRUE(same_samples(*next, expected[1]));
    released_data = next->xyz_mm.data;
  }  // frame 1 released
  for (int f = 2; f < 5; ++f) {
    auto frame = reader->decode_frame(f);
    ASSERT_TRUE(frame.is_ok());
    EXPECT_EQ(frame->xyz_mm.data, released_data) << "frame " << f;  // reused
    EXPECT_TRUE(same_samples(*frame, expected[f])) << "frame " << f;
    EXPECT_EQ(frame->index, f);
  }
  EXPECT_TRUE(same_samples(*held, expected[0]));  // never written over
  EXPECT_EQ(held->xyz_mm.data, held_data);
}

TEST(BFrames, TrailingCandidatesWithoutAFollowingAnchorAreCodedAsP) {
  const auto frames = moving_video(32, 6);
  const SequenceInfo info = info_for(frames);
  for (const int count : {6, 3, 1}) {
    EncoderOptions o;
    o.bframes = 3;
    o.lossless = true;
    o.preset = Preset::kFast;
    const std::vector<GeometryImage> part(frames.begin(), frames.begin() + count);
    auto bytes = encode_gvid(part, info, o);
    ASSERT_TRUE(bytes.is_ok());
    auto reader = open_bytes(*bytes);
    ASSERT_TRUE(reader);
    EXPECT_EQ(types_of(*reader), count == 6 ? "IBBBPP" : (count == 3 ? "IPP" : "I"));
    for (int f = 0; f < count; ++f) {
      auto decoded = reader->decode_frame(f);
      ASSERT_TRUE(decoded.is_ok()) << decoded.status().message();
      EXPECT_TRUE(
          same_samples(*decoded, dequantize_geometry(quantize_geometry(part[f], info), info, f)));
    }
  }
}

TEST(BFrames, ADamagedAnchorFailsItsDependentFramesNamingItAndTheRestDecode) {
  const auto frames = moving_video(32, 9);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.bframes = 1;
  o.intra_period = 6;
  o.qp = 4;
  o.preset = Preset::kFast;
  auto bytes = encode_gvid(frames, info, o);
  ASSERT_TRUE(bytes.is_ok());
  auto reader = open_bytes(*bytes);
  ASSERT_TRUE(reader);
  ASSERT_EQ(types_of(*reader), "IBPBPBIBP");
  size_t offset = 0;
  const std::string_view p4 = packet_of(*bytes, *reader, 4, &offset);
  std::string bad = *bytes;
  bad[offset + p4.size() - 3] ^= 0x10;  // the payload of P frame 4
  auto damaged = open_bytes(bad);
  ASSERT_TRUE(damaged);
  for (int f = 0; f < 9; ++f) {
    auto frame = damaged->decode_frame(f);
    const bool depends_on_4 = f >= 3 && f <= 5;  // B3 (L1), P4 itself, B5 (L0)
    if (!depends_on_4) {
      EXPECT_TRUE(frame.is_ok()) << f << ": " << frame.status().message();
      continue;
    }
    ASSERT_FALSE(frame.is_ok()) << f;
    const std::string& m = frame.status().message();
    if (f == 4)
      EXPECT_NE(m.find("b.gvid: frame 4: payload CRC mismatch"), std::string::npos) << m;
    else
      EXPECT_NE(m.find("frame " + std::to_string(f) + ": reference frame 4: payload CRC mismatch"),
                std::string::npos)
          << m;
  }
}

TEST(BFrames, BadBSyntaxIsRejectedWithAMessage) {
  const auto frames = moving_video(32, 3);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.bframes = 1;
  o.qp = 4;
  o.preset = Preset::kFast;
  auto bytes = encode_gvid(frames, info, o);
  ASSERT_TRUE(bytes.is_ok());
  auto reader = open_bytes(*bytes);
  ASSERT_TRUE(reader);
  ASSERT_EQ(types_of(*reader), "IBP");
  size_t i_offset = 0, b_offset = 0;
  const std::string i_packet(packet_of(*bytes, *reader, 0, &i_offset));
  const std::string b_packet(packet_of(*bytes, *reader, 1, &b_offset));
  // A B packet decoded without its anchors.
  auto alone = decode_frame_packet(b_packet, info, 1);
  ASSERT_FALSE(alone.is_ok());
  EXPECT_NE(alone.status().message().find("B frame without the anchor frame before it"),
            std::string::npos)
      << alone.status().message();
  std::vector<SamplePlane> i_planes;
  ASSERT_TRUE(decode_frame_packet(i_packet, info, 0, nullptr, &i_planes).is_ok());
  auto one_side = decode_frame_packet(b_packet, info, 1, &i_planes);
  ASSERT_FALSE(one_side.is_ok());
  EXPECT_NE(one_side.status().message().find("B frame without the anchor frame after it"),
            std::string::npos)
      << one_side.status().message();
  // A stream whose B frame lost the anchor after it (the P packet and the index cut off).
  const std::string cut =
      bytes->substr(0, static_cast<size_t>(reader->header_bytes())) + i_packet + b_packet;
  auto r = open_bytes(cut);
  ASSERT_TRUE(r);
  EXPECT_TRUE(r->index_rebuilt());
  EXPECT_TRUE(r->decode_frame(0).is_ok());
  auto b = r->decode_frame(1);
  ASSERT_FALSE(b.is_ok());
  EXPECT_NE(b.status().message().find("frame 1: B frame without an anchor frame after it"),
            std::string::npos)
      << b.status().message();
  // A B frame with a P-frame tool flag.
  {
    std::string packet = b_packet;
    auto h = format::read_packet_header(packet);
    ASSERT_TRUE(h.is_ok());
    h->flags |= format::kFrameTdPrediction;
    packet.replace(0, h->header_size, format::write_packet_header(*h));
    auto p_planes = decode_frame_packet(b_packet, info, 1, &i_planes, nullptr, &i_planes);
    ASSERT_TRUE(p_planes.is_ok()) << p_planes.status().message();
    auto flagged = decode_frame_packet(packet, info, 1, &i_planes, nullptr, &i_planes);
    ASSERT_FALSE(flagged.is_ok());
    EXPECT_NE(flagged.status().message().find("in a B frame"), std::string::npos)
        << flagged.status().message();
  }
  // Random damage inside the B payload (CRCs fixed up, so that it reaches the macroblock
  // layer): every result is frames or a Status, never a crash (run under ASan).
  std::mt19937 rng(3);
  int failures = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const std::string packet = testing::damage_payload(b_packet, rng, 1 + trial % 4, 8);
    auto d = decode_frame_packet(packet, info, 1, &i_planes, nullptr, &i_planes);
    if (!d.is_ok()) {
      ++failures;
      EXPECT_NE(d.status().message().find("plane"), std::string::npos) << d.status().message();
    }
  }
  EXPECT_GT(failures, 0);
}

TEST(BFrames, ZeroBFramesOrIntraOnlyWriteNoBFrame) {
  const auto frames = moving_video(48, 4);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.preset = Preset::kFast;
  o.qp = 6;
  o.bframes = 0;
  auto reader = open_bytes(encode_gvid(frames, info, o).value());
  ASSERT_TRUE(reader);
  for (int f = 0; f < 4; ++f)
    EXPECT_EQ(reader->frame_type(f), f == 0 ? FrameType::kIntra : FrameType::kPredicted) << f;
  // B frames asked for but every frame an anchor (intra only): no B frame, profile intra.
  o.intra_only = true;
  o.bframes = 2;
  reader = open_bytes(encode_gvid(frames, info, o).value());
  ASSERT_TRUE(reader);
  EXPECT_EQ(reader->format().profile, Profile::kIntra);
  for (int f = 0; f < 4; ++f) EXPECT_EQ(reader->frame_type(f), FrameType::kIntra) << f;
}

TEST(BFrames, RateControlSetsBFramesAboveTheirAnchorAndMeetsTheRate) {
  const auto frames = moving_video(48, 9, 0.5);
  const SequenceInfo info = info_for(frames);
  EncoderOptions o;
  o.bframes = 2;
  o.b_qp_offset = 4;
  o.preset = Preset::kFast;
  o.bitrate_kbps = 400;
  testing::TempDir dir;
  auto writer = GvidWriter::create(dir / "r.gvid", info, o);
  ASSERT_TRUE(writer.is_ok()) << writer.status().message();
  size_t returned = 0;
  for (const auto& f : frames) {
    auto done = (*writer)->write(f);
    ASSERT_TRUE(done.is_ok()) << done.status().message();
    returned += done->size();
  }
  auto rest = (*writer)->finish();
  ASSERT_TRUE(rest.is_ok());
  EXPECT_EQ(returned + rest->size(), frames.size());
  const auto& types = (*writer)->frame_types();
  const auto& qp = (*writer)->frame_qp();
  ASSERT_EQ(types.size(), 9u);
  for (int f = 1; f < 9; ++f)
    if (types[f] == FrameType::kBidirectional) {
      // Coded right after the anchor that follows it: that anchor's QP + the offset (it is a
      // P frame here: frames 3 and 6).
      const int anchor = (f / 3 + 1) * 3;
      ASSERT_EQ(types[anchor], FrameType::kPredicted);
      EXPECT_GE(qp[f], std::min(51, qp[anchor] + 4)) << f;
    }
  EXPECT_LE((*writer)->rate_controller()->max_fullness_bits(),
            (*writer)->rate_controller()->buffer_bits());
  auto reader = GvidReader::open(dir / "r.gvid");
  ASSERT_TRUE(reader.is_ok());
  for (int f = 0; f < 9; ++f) {
    auto d = (*reader)->decode_frame(f);
    EXPECT_TRUE(d.is_ok()) << f << ": " << d.status().message();
  }
}

TEST(BFrames, OptionsOutOfRangeAreRejectedByName) {
  EncoderOptions o;
  o.bframes = 4;
  EXPECT_NE(o.check().message().find("B frames 4 out of range (0..3"), std::string::npos);
  o.bframes = -2;
  EXPECT_FALSE(o.check().is_ok());
  // Automatic: one B frame in lossy streams, none in lossless and near-lossless ones.
  o.bframes = -1;
  EXPECT_TRUE(o.check().is_ok());
  EXPECT_EQ(o.b_frames(), 1);
  o.lossless = true;
  EXPECT_EQ(o.b_frames(), 0);
  o.lossless = false;
  o.max_error_mm = 0.1;
  EXPECT_EQ(o.b_frames(), 0);
  o.max_error_mm = 0;
  o.bframes = 1;
  EXPECT_TRUE(o.check().is_ok());
  o.b_qp_offset = 13;
  EXPECT_NE(o.check().message().find("B-frame QP offset 13 out of range"), std::string::npos);
}

}  // namespace
}  // namespace gvkit::codec
