// .gvid streams end to end: lossless and lossy round trips (error within the quantizer's bound,
// in mm), the file writer's atomic output, the seek index and its rebuild by a scan, and damage:
// corrupt, truncated and bit-flipped streams give a Status naming the frame and field while the
// other intra frames still decode.
#include <cmath>
#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "geometry_video_material.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/transform.hpp"
#include "support/test_support.hpp"

namespace gvkit::codec {
namespace {

std::vector<GeometryImage> small_video(int frames = 3) {
  testing::GeometryVideoOptions o;
  o.size = 40;  // not a multiple of 16: exercises padding
  o.frames = frames;
  return testing::make_analytic_video(o);
}

SequenceInfo info_for(const std::vector<GeometryImage>& frames, int bit_depth = 16) {
  auto info = make_sequence_info(frames, bit_depth, 30.0);
  GVKIT_CHECK(info.is_ok(), info.status().message());
  return std::move(info).value();
}

std::unique_ptr<GvidReader> open_bytes(std::string bytes) {
  auto reader = GvidReader::open_memory(std::move(bytes), "test.gvid");
  if (!reader.is_ok()) ADD_FAILURE() << reader.status().message();
  return reader.is_ok() ? std::move(reader).value() : nullptr;
}

TEST(GvidStream, LosslessDecodesToTheQuantizedInputExactly) {
  for (int bit_depth : {16, 12, 8}) {
    const auto frames = small_video();
    const SequenceInfo info = info_for(frames, bit_depth);
    EncoderOptions options;
    options.lossless = true;
    options.bit_depth = bit_depth;
    options.preset = Preset::kFast;
    auto bytes = encode_gvid(frames, info, options);
    ASSERT_TRUE(bytes.is_ok()) << bytes.status().message();
    auto reader = open_bytes(*bytes);
    ASSERT_TRUE(reader);
    ASSERT_EQ(reader->frame_count(), 3);
    EXPECT_FALSE(reader->index_rebuilt());
    for (int f = 0; f < 3; ++f) {
      auto decoded = reader->decode_frame(f);
      ASSERT_TRUE(decoded.is_ok()) << decoded.status().message();
      const GeometryImage expected =
          dequantize_geometry(quantize_geometry(frames[f], info), info, f);
      const GeometryError e = geometry_error(expected, *decoded);
      EXPECT_EQ(e.max_mm, 0.0) << "bits " << bit_depth;
      // And the quantization itself is within half a step per axis.
      const GeometryError q = geometry_error(frames[f], *decoded);
      EXPECT_LE(q.max_mm, info.step_mm() * std::sqrt(3.0) / 2 * 1.001 + 1e-4);
      EXPECT_EQ(cv::countNonZero(decoded->domain_mask != frames[f].domain_mask), 0);
    }
  }
}

TEST(GvidStream, LossyErrorIsWithinTheQuantizerBound) {
  const auto frames = small_video(2);
  const SequenceInfo info = info_for(frames);
  for (int qp : {-30, 0, 20})
    for (Preset preset : {Preset::kFast, Preset::kSlow}) {
      EncoderOptions options;
      options.qp = qp;
      options.preset = preset;
      auto bytes = encode_gvid(frames, info, options);
      ASSERT_TRUE(bytes.is_ok()) << bytes.status().message();
      auto reader = open_bytes(*bytes);
      ASSERT_TRUE(reader);
      for (int f = 0; f < 2; ++f) {
        auto decoded = reader->decode_frame(f);
        ASSERT_TRUE(decoded.is_ok()) << decoded.status().message();
        const GeometryError e = geometry_error(frames[f], *decoded);
        // Per axis: 8x8 transform bound of the transform test, plus half a step of quantization.
        const double per_axis =
            (8 * quantizer_step(options.qp_prime()) * (2.0 / 3.0) + 6 + 0.5) * info.step_mm();
        EXPECT_LE(e.max_mm, per_axis * std::sqrt(3.0)) << "qp " << qp;
        EXPECT_GT(e.pixels, 0);
      }
    }
}

TEST(GvidStream, TexturePlaneRoundTripsAt8Bits) {
  auto frames = small_video(2);
  for (auto& f : frames) {
    f.texture.create(f.xyz_mm.size(), CV_32F);
    for (int y = 0; y < f.texture.rows; ++y)
      for (int x = 0; x < f.texture.cols; ++x)
        f.texture.at<float>(y, x) = ((x * 7 + y * 3) % 256) / 255.0f;
  }
  const SequenceInfo info = info_for(frames);
  ASSERT_TRUE(info.has_texture);
  EncoderOptions options;
  options.lossless = true;
  options.preset = Preset::kFast;
  auto bytes = encode_gvid(frames, info, options);
  ASSERT_TRUE(bytes.is_ok()) << bytes.status().message();
  auto reader = open_bytes(*bytes);
  ASSERT_TRUE(reader);
  EXPECT_TRUE(reader->info().has_texture);
  auto decoded = reader->decode_frame(1);
  ASSERT_TRUE(decoded.is_ok()) << decoded.status().message();
  ASSERT_EQ(decoded->texture.size(), frames[1].texture.size());
  EXPECT_LE(cv::norm(decoded->texture, frames[1].texture, cv::NORM_INF), 0.5 / 255 + 1e-6);
}

TEST(GvidStream, IctFaceVideoRoundTripsLosslessly) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  testing::GeometryVideoOptions o;
  o.size = 64;
  o.frames = 2;
  auto frames = testing::make_ict_face_video(data / "ict-facekit", o);
  ASSERT_TRUE(frames.is_ok()) << frames.status().message();
  const SequenceInfo info = info_for(*frames);
  // The face fills most of its UV tile; the rest is the domain's outside.
  EXPECT_GT(info.domain_pixels(), 64 * 64 * 8 / 10);
  EXPECT_LT(info.domain_pixels(), 64 * 64);
  EXPECT_GT(info.box_diagonal_mm(), 250.0);
  EXPECT_LT(info.box_diagonal_mm(), 500.0);
  EncoderOptions options;
  options.lossless = true;
  options.preset = Preset::kFast;
  auto bytes = encode_gvid(*frames, info, options);
  ASSERT_TRUE(bytes.is_ok());
  auto reader = open_bytes(*bytes);
  ASSERT_TRUE(reader);
  for (int f = 0; f < 2; ++f) {
    auto decoded = reader->decode_frame(f);
    ASSERT_TRUE(decoded.is_ok());
    EXPECT_LE(geometry_error((*frames)[f], *decoded).max_mm, info.step_mm());
  }
}

TEST(GvidStream, GeometryModesFlagChangesTheStreamButBothDecode) {
  const auto frames = small_video(1);
  const SequenceInfo info = info_for(frames);
  EncoderOptions on, off;
  on.lossless = off.lossless = true;
  off.geometry_modes = false;
  auto a = encode_gvid(frames, info, on), b = encode_gvid(frames, info, off);
  ASSERT_TRUE(a.is_ok() && b.is_ok());
  EXPECT_NE(*a, *b);
  for (const std::string* bytes : {&*a, &*b}) {
    auto reader = open_bytes(*bytes);
    ASSERT_TRUE(reader);
    auto decoded = reader->decode_frame(0);
    ASSERT_TRUE(decoded.is_ok()) << decoded.status().message();
  }
}

TEST(GvidStream, FileWriterRenamesIntoPlaceAndReaderSeeksByIndex) {
  testing::TempDir dir;
  const auto frames = small_video();
  const SequenceInfo info = info_for(frames);
  EncoderOptions options;
  options.preset = Preset::kFast;
  const auto path = dir / "take.gvid";
  {
    auto writer = GvidWriter::create(path, info, options);
    ASSERT_TRUE(writer.is_ok()) << writer.status().message();
    for (const auto& f : frames) ASSERT_TRUE((*writer)->write(f).is_ok());
    EXPECT_FALSE(std::filesystem::exists(path));  // still under its temporary name
    ASSERT_TRUE((*writer)->finish().is_ok());
  }
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
  auto reader = GvidReader::open(path);
  ASSERT_TRUE(reader.is_ok()) << reader.status().message();
  EXPECT_EQ((*reader)->frame_count(), 3);
  EXPECT_GT((*reader)->frame_bits(2), 0);
  auto last = (*reader)->decode_frame(2);
  ASSERT_TRUE(last.is_ok());
  EXPECT_EQ(last->index, 2);
  EXPECT_FALSE((*reader)->decode_frame(3).is_ok());
}

TEST(GvidStream, AbandonedWriterLeavesNothing) {
  testing::TempDir dir;
  const auto frames = small_video(1);
  {
    auto writer = GvidWriter::create(dir / "x.gvid", info_for(frames), EncoderOptions{});
    ASSERT_TRUE(writer.is_ok());
  }
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 0);
}

TEST(GvidStream, OptionsOutOfRangeAreRejectedByName) {
  EncoderOptions o;
  o.qp = 52;
  EXPECT_NE(o.check().message().find("qp 52"), std::string::npos);
  o.qp = -49;
  EXPECT_FALSE(o.check().is_ok());
  o.qp = -48;
  EXPECT_TRUE(o.check().is_ok());
  o.bit_depth = 17;
  EXPECT_NE(o.check().message().find("bit depth"), std::string::npos);
}

TEST(GvidStream, PFramesFollowTheIntraPeriodAndDecodeInAnyOrder) {
  const auto frames = small_video(5);
  const SequenceInfo info = info_for(frames);
  EncoderOptions options;
  options.qp = -6;
  options.intra_period = 3;  // I P P I P
  options.bframes = 0;       // P frames only (B frames: bframe_test.cpp)
  options.preset = Preset::kFast;
  auto bytes = encode_gvid(frames, info, options);
  ASSERT_TRUE(bytes.is_ok()) << bytes.status().message();
  auto sequential = open_bytes(*bytes);
  auto random = open_bytes(*bytes);
  ASSERT_TRUE(sequential && random);
  const format::FrameType I = format::FrameType::kIntra, P = format::FrameType::kPredicted;
  const format::FrameType expected[5] = {I, P, P, I, P};
  for (int f = 0; f < 5; ++f) EXPECT_EQ(sequential->frame_type(f), expected[f]);
  std::vector<GeometryImage> in_order;
  for (int f = 0; f < 5; ++f) {
    auto frame = sequential->decode_frame(f);
    ASSERT_TRUE(frame.is_ok()) << frame.status().message();
    in_order.push_back(*frame);
  }
  for (int f : {4, 2, 0, 1, 3, 2}) {
    auto frame = random->decode_frame(f);
    ASSERT_TRUE(frame.is_ok()) << frame.status().message();
    EXPECT_EQ(geometry_error(in_order[f], *frame).max_mm, 0.0) << "frame " << f;
  }
  // P frames cost fewer bits than the intra frames of this slowly changing surface.
  EXPECT_LT(sequential->frame_bits(1), sequential->frame_bits(0));
}

TEST(GvidStream, PFramesAreLosslessToo) {
  const auto frames = small_video(3);
  const SequenceInfo info = info_for(frames);
  for (Preset preset : {Preset::kFast, Preset::kSlow}) {
    EncoderOptions options;
    options.lossless = true;
    options.preset = preset;
    auto bytes = encode_gvid(frames, info, options);
    ASSERT_TRUE(bytes.is_ok());
    auto reader = open_bytes(*bytes);
    ASSERT_TRUE(reader);
    ASSERT_EQ(reader->frame_type(2), format::FrameType::kPredicted);
    for (int f = 0; f < 3; ++f) {
      const GeometryImage expected =
          dequantize_geometry(quantize_geometry(frames[f], info), info, f);
      EXPECT_EQ(geometry_error(expected, reader->decode_frame(f).value()).max_mm, 0.0);
    }
  }
}

// The offset of the payload of the packet at `packet` in `bytes`.
size_t payload_at(const std::string& bytes, size_t packet) {
  return packet + format::read_packet_header(std::string_view(bytes).substr(packet))->header_size;
}

TEST(GvidStream, CorruptPFrameCostsFramesUpToTheNextIntraFrame) {
  const auto frames = small_video(4);
  EncoderOptions options;
  options.preset = Preset::kFast;
  options.intra_period = 2;  // I P I P
  options.bframes = 0;       // P frames only (B frames: bframe_test.cpp)
  auto bytes = encode_gvid(frames, info_for(frames), options);
  ASSERT_TRUE(bytes.is_ok());
  auto clean = open_bytes(*bytes);
  ASSERT_TRUE(clean);
  const size_t frame1 = static_cast<size_t>(clean->header_bytes() + clean->frame_bits(0) / 8);
  std::string bad = *bytes;
  bad[payload_at(bad, frame1) + 5] ^= 0x10;
  auto reader = open_bytes(bad);
  ASSERT_TRUE(reader);
  auto f1 = reader->decode_frame(1);
  ASSERT_FALSE(f1.is_ok());
  EXPECT_NE(f1.status().message().find("frame 1: payload CRC mismatch"), std::string::npos);
  EXPECT_TRUE(reader->decode_frame(2).is_ok());
  EXPECT_TRUE(reader->decode_frame(3).is_ok());
  // In I P P P the damage propagates to the end of the chain, named as such.
  options.intra_period = 30;
  bytes = encode_gvid(frames, info_for(frames), options);
  bad = *bytes;
  auto clean2 = open_bytes(*bytes);
  const size_t frame1b = static_cast<size_t>(clean2->header_bytes() + clean2->frame_bits(0) / 8);
  bad[payload_at(bad, frame1b) + 5] ^= 0x10;
  auto reader2 = open_bytes(bad);
  auto f3 = reader2->decode_frame(3);
  ASSERT_FALSE(f3.is_ok());
  EXPECT_NE(f3.status().message().find("frame 3: reference frame 1: payload CRC mismatch"),
            std::string::npos)
      << f3.status().message();
  EXPECT_TRUE(reader2->decode_frame(0).is_ok());
}

// Format 1.6: with several reference frames a damaged anchor fails every frame whose references
// reach it (named as the reference frame), but never across an intra frame.
TEST(GvidStream, CorruptAnchorFailsTheFramesThatReferenceIt) {
  const auto frames = small_video(6);
  EncoderOptions options;
  options.preset = Preset::kFast;
  options.bframes = 0;
  options.refs = 3;
  options.intra_period = 3;  // I P P I P P
  auto bytes = encode_gvid(frames, info_for(frames), options);
  ASSERT_TRUE(bytes.is_ok());
  auto clean = open_bytes(*bytes);
  ASSERT_TRUE(clean);
  EXPECT_EQ(clean->frame_references(2), 2);  // frames 1 and 0
  EXPECT_EQ(clean->frame_references(4), 1);  // frame 3 only: not past the intra frame
  EXPECT_EQ(clean->frame_references(5), 2);
  const size_t frame1 = static_cast<size_t>(clean->header_bytes() + clean->frame_bits(0) / 8);
  std::string bad = *bytes;
  bad[payload_at(bad, frame1) + 5] ^= 0x10;
  auto reader = open_bytes(bad);
  ASSERT_TRUE(reader);
  auto f2 = reader->decode_frame(2);
  ASSERT_FALSE(f2.is_ok());
  EXPECT_NE(f2.status().message().find("frame 2: reference frame 1: payload CRC mismatch"),
            std::string::npos)
      << f2.status().message();
  EXPECT_TRUE(reader->decode_frame(0).is_ok());
  for (int f = 3; f < 6; ++f) EXPECT_TRUE(reader->decode_frame(f).is_ok()) << f;
}

class DamagedStream : public ::testing::Test {
 protected:
  void SetUp() override {
    frames_ = small_video(3);
    EncoderOptions options;
    options.preset = Preset::kFast;
    options.intra_only = true;
    auto bytes = encode_gvid(frames_, info_for(frames_), options);
    ASSERT_TRUE(bytes.is_ok());
    bytes_ = *bytes;
    auto reader = open_bytes(bytes_);
    ASSERT_TRUE(reader);
    header_size_ = static_cast<size_t>(reader->header_bytes());
    frame_bytes_ = reader->frame_bits(0) / 8;
  }
  std::vector<GeometryImage> frames_;
  std::string bytes_;
  size_t header_size_ = 0;
  int64_t frame_bytes_ = 0;
};

TEST_F(DamagedStream, CorruptPayloadCostsThatFrameOnly) {
  std::string bad = bytes_;
  const size_t frame1 = header_size_ + frame_bytes_;
  bad[payload_at(bad, frame1) + 10] ^= 0x40;
  auto reader = open_bytes(bad);
  ASSERT_TRUE(reader);
  auto f1 = reader->decode_frame(1);
  ASSERT_FALSE(f1.is_ok());
  EXPECT_NE(f1.status().message().find("test.gvid: frame 1: payload CRC mismatch"),
            std::string::npos)
      << f1.status().message();
  EXPECT_TRUE(reader->decode_frame(0).is_ok());
  EXPECT_TRUE(reader->decode_frame(2).is_ok());
}

TEST_F(DamagedStream, MissingIndexIsRebuiltByAScan) {
  const std::string no_index = bytes_.substr(0, bytes_.size() - format::kTrailerSize - 3);
  auto reader = open_bytes(no_index);
  ASSERT_TRUE(reader);
  EXPECT_TRUE(reader->index_rebuilt());
  ASSERT_EQ(reader->frame_count(), 3);
  for (int f = 0; f < 3; ++f) EXPECT_TRUE(reader->decode_frame(f).is_ok());
}

TEST_F(DamagedStream, TrailerOffsetNearTheTopOfTheRangeIsRejectedNotThrown) {
  // A trailer whose index offset + 12 wraps around 2^64 (found by the fuzzer): the index is
  // rejected ("index: offset out of range") and rebuilt by a scan instead of throwing.
  for (const uint64_t offset : {~uint64_t{0}, ~uint64_t{0} - 5, uint64_t{1} << 63}) {
    std::string bad = bytes_;
    const size_t at = bad.size() - format::kTrailerSize;
    for (int i = 0; i < 8; ++i) bad[at + i] = static_cast<char>((offset >> (8 * i)) & 0xff);
    uint64_t index_offset = 0;
    auto index = format::read_index(bad, header_size_, &index_offset);
    ASSERT_FALSE(index.is_ok());
    EXPECT_NE(index.status().message().find("index: offset out of range"), std::string::npos)
        << index.status().message();
    auto reader = open_bytes(bad);
    ASSERT_TRUE(reader);
    EXPECT_TRUE(reader->index_rebuilt());
    EXPECT_EQ(reader->frame_count(), 3);
  }
}

TEST_F(DamagedStream, DamagedPacketHeaderLosesOnePacketInTheScan) {
  std::string bad = bytes_.substr(0, bytes_.size() - format::kTrailerSize);  // no index either
  bad[header_size_ + frame_bytes_ + 9] ^= 0x01;  // frame 1's frame number: header CRC fails
  auto reader = open_bytes(bad);
  ASSERT_TRUE(reader);
  ASSERT_EQ(reader->frame_count(), 2);
  EXPECT_TRUE(reader->decode_frame(0).is_ok());
  auto second = reader->decode_frame(1);
  ASSERT_TRUE(second.is_ok());
}

TEST_F(DamagedStream, DamagedHeaderFailsOpenNamingTheHeader) {
  std::string bad = bytes_;
  bad[14] ^= 0x01;
  auto reader = GvidReader::open_memory(bad, "test.gvid");
  ASSERT_FALSE(reader.is_ok());
  EXPECT_NE(reader.status().message().find("test.gvid: header: CRC mismatch"), std::string::npos);
  auto not_gvid = GvidReader::open_memory("hello world, not a stream", "x.gvid");
  EXPECT_NE(not_gvid.status().message().find("magic"), std::string::npos);
}

TEST_F(DamagedStream, EveryTruncationFailsCleanlyOrDecodes) {
  for (size_t len = 0; len < bytes_.size(); len += 37) {
    auto reader = GvidReader::open_memory(bytes_.substr(0, len), "t.gvid");
    if (!reader.is_ok()) continue;
    for (int64_t f = 0; f < (*reader)->frame_count(); ++f) {
      auto frame = (*reader)->decode_frame(f);
      if (!frame.is_ok()) {
        EXPECT_NE(frame.status().message().find("frame " + std::to_string(f)), std::string::npos);
      }
    }
  }
}

TEST_F(DamagedStream, RandomBitFlipsNeverCrashAndNameTheFrame) {
  std::mt19937 rng(11);
  int failed_frames = 0;
  for (int trial = 0; trial < 60; ++trial) {
    std::string bad = bytes_;
    const size_t pos = header_size_ + rng() % (bad.size() - header_size_);
    bad[pos] = static_cast<char>(bad[pos] ^ (1 << (rng() % 8)));
    auto reader = GvidReader::open_memory(bad, "t.gvid");
    ASSERT_TRUE(reader.is_ok()) << reader.status().message();
    for (int64_t f = 0; f < (*reader)->frame_count(); ++f) {
      auto frame = (*reader)->decode_frame(f);
      if (frame.is_ok()) continue;
      ++failed_frames;
      EXPECT_NE(frame.status().message().find("t.gvid: frame " + std::to_string(f)),
                std::string::npos);
    }
  }
  EXPECT_GT(failed_frames, 30);
}

}  // namespace
}  // namespace gvkit::codec
