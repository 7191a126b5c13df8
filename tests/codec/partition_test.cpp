// Inter partitions (flags2 bit 5, docs/bitstream.md 4.11). The decoder (GvidReader, in display
// order and by random access) reproduces the encoder's reconstruction exactly in both presets,
// with P and B frames and with the other tools on; content whose halves move differently is coded
// with partitions, and costs less with them in the slow preset; corrupt partition syntax is
// rejected with a message; the fast preset and intra-only streams never use them.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/cabac_encoder.hpp"
#include "gvkit/codec/crc32.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/motion_search.hpp"
#include "gvkit/codec/partition_search.hpp"
#include "gvkit/codec/plane_coding.hpp"
#include "gvkit/codec/sequence_encoder.hpp"

namespace gvkit::codec {
namespace {

// The analytic surface, the block x < 40, y < 24 moving by (0.75, 0.375) pixels per frame and
// the rest by (-1.25, -0.625): motion boundaries inside macroblocks (8 samples into them).
std::vector<GeometryImage> video(int size, int frames) {
  testing::GeometryVideoOptions o;
  o.size = size;
  o.frames = frames;
  auto a = testing::make_analytic_video(o);
  auto b = a;
  testing::move_in_picture(&a, 0.75);
  testing::move_in_picture(&b, -1.25);
  for (size_t f = 0; f < a.size(); ++f)
    for (int y = 24; y < size; ++y)
      for (int x = 0; x < size; ++x)
        a[f].xyz_mm.at<cv::Vec3f>(y, x) = b[f].xyz_mm.at<cv::Vec3f>(y, x);
  for (size_t f = 0; f < a.size(); ++f)
    for (int y = 0; y < 24; ++y)
      for (int x = 40; x < size; ++x)
        a[f].xyz_mm.at<cv::Vec3f>(y, x) = b[f].xyz_mm.at<cv::Vec3f>(y, x);
  return a;
}

// Encodes with SequenceEncoder and encode_gvid; expects the packets to agree and GvidReader to
// reproduce every reconstruction in display order and by random access. Returns the number of
// partitioned (16x8, 8x16, 8x8) macroblocks the encoder coded.
int64_t expect_round_trip(const std::vector<GeometryImage>& frames, const SequenceInfo& info,
                          const EncoderOptions& o, const std::string& what) {
  auto encoder = SequenceEncoder::create(info, o);
  EXPECT_TRUE(encoder.is_ok()) << what;
  if (!encoder.is_ok()) return 0;
  std::vector<GeometryImage> recon(frames.size());
  std::string packets;
  int64_t partitioned = 0;
  const auto keep = [&](std::vector<SequenceFrame> done) {
    for (SequenceFrame& f : done) {
      packets += f.packet;
      for (const PlaneCodingStats& s : f.stats.planes)
        partitioned += s.partition_mbs[1] + s.partition_mbs[2] + s.partition_mbs[3];
      auto header = format::read_packet_header(f.packet);
      EXPECT_TRUE(header.is_ok());
      // Bit 5 in the P frames only.
      EXPECT_EQ((header->flags2 & format::kFrame2Partitions) != 0,
                o.use_partitions() && f.type == format::FrameType::kPredicted)
          << what << " frame " << f.number;
      recon[f.number] = std::move(f.reconstruction);
    }
  };
  for (const GeometryImage& f : frames) {
    auto done = (*encoder)->push(f);
    EXPECT_TRUE(done.is_ok()) << what << ": " << done.status().message();
    if (!done.is_ok()) return 0;
    keep(std::move(done).value());
  }
  auto rest = (*encoder)->flush();
  EXPECT_TRUE(rest.is_ok()) << what;
  keep(std::move(rest).value());
  auto bytes = encode_gvid(frames, info, o);
  EXPECT_TRUE(bytes.is_ok()) << what;
  if (!bytes.is_ok()) return 0;
  const std::string header = format::write_file_header(info, o.resolved_profile());
  EXPECT_EQ(bytes->substr(header.size(), packets.size()), packets) << what;
  for (int pass = 0; pass < 2; ++pass) {
    auto reader = GvidReader::open_memory(*bytes, what);
    EXPECT_TRUE(reader.is_ok()) << what;
    if (!reader.is_ok()) return 0;
    const int64_t n = (*reader)->frame_count();
    for (int64_t i = 0; i < n; ++i) {
      const int64_t f = pass == 0 ? i : (i * 5 + 3) % n;  // display order, then jumps
      auto image = (*reader)->decode_frame(f);
      EXPECT_TRUE(image.is_ok()) << what << " frame " << f << ": " << image.status().message();
      if (!image.is_ok()) return 0;
      EXPECT_TRUE(testing::same_samples(image->xyz_mm, recon[f].xyz_mm)) << what << " frame " << f;
    }
  }
  return partitioned;
}

TEST(Partitions, DecoderReproducesTheEncoderInEveryConfiguration) {
  const auto frames = video(64, 6);
  const SequenceInfo info = testing::info_for(frames);
  for (Preset preset : {Preset::kFast, Preset::kSlow})
    for (int mode = 0; mode < 4; ++mode)  // lossy QP 0, lossy QP 12, lossless, near-lossless
      for (int bframes : {0, 1}) {
        if (preset == Preset::kFast && mode > 0) continue;  // the fast preset codes 16x16 only
        EncoderOptions o;
        o.preset = preset;
        o.qp = mode == 1 ? 12 : 0;
        o.lossless = mode == 2;
        o.max_error_mm = mode == 3 ? 0.05 : 0;
        o.bframes = bframes;
        o.refs = mode == 1 ? 1 : 3;
        o.shared_motion = bframes == 0;
        o.joint_motion_search = bframes == 0;
        // Value prediction maps reference 0 (the partitions predict from the mapped planes).
        o.value_prediction = mode == 0 ? ValuePrediction::kAffine : ValuePrediction::kNone;
        o.partitions = true;
        const std::string what = std::string(preset_name(preset)) + " mode " +
                                 std::to_string(mode) + " bframes " + std::to_string(bframes);
        const int64_t partitioned = expect_round_trip(frames, info, o, what);
        // (Lossless: TD prediction takes the inter macroblocks of this video.)
        if (preset == Preset::kSlow && mode != 2) {
          EXPECT_GT(partitioned, 0) << what;
        }
      }
}

// Slow preset: with the partitions the two-motion video's rate-distortion point lies above the
// curve without them (through QP 3 and 6, in PSNR over log2 rate; at the same QP the partitions
// may spend a few more bytes on a clearly higher PSNR).
TEST(Partitions, TwoMotionsCostLessWithPartitions) {
  const auto frames = video(64, 5);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.preset = Preset::kSlow;
  o.p_qp_offset = 6;  // P frames at QP 12, where the test was made
  o.bframes = 0;
  const auto point = [&](int qp, bool partitions) {
    o.qp = qp;
    o.partitions = partitions;
    const auto bytes = encode_gvid(frames, info, o);
    GVKIT_CHECK(bytes.is_ok(), bytes.status().message());
    return std::pair<double, double>(static_cast<double>(bytes->size()),
                                     testing::stream_psnr_db(frames, info, *bytes));
  };
  const auto [off3_bytes, off3_psnr] = point(3, false);
  const auto [off6_bytes, off6_psnr] = point(6, false);
  const auto [on_bytes, on_psnr] = point(6, true);
  const double slope = (off3_psnr - off6_psnr) / std::log2(off3_bytes / off6_bytes);
  ASSERT_GT(slope, 0);
  EXPECT_GT(on_psnr, off6_psnr + slope * std::log2(on_bytes / off6_bytes))
      << "off: " << off3_bytes << " B " << off3_psnr << " dB, " << off6_bytes << " B " << off6_psnr
      << " dB; on: " << on_bytes << " B " << on_psnr << " dB";
}

TEST(Partitions, FastPresetAndIntraOnlyNeverUseThem) {
  const auto frames = video(48, 3);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.preset = Preset::kFast;
  o.bframes = 0;
  // The fast preset codes 16x16 only: the option changes nothing.
  auto fast_off = encode_gvid(frames, info, o);
  o.partitions = true;
  EXPECT_FALSE(o.use_partitions());
  auto fast_on = encode_gvid(frames, info, o);
  ASSERT_TRUE(fast_off.is_ok() && fast_on.is_ok());
  EXPECT_TRUE(*fast_on == *fast_off);
  o.preset = Preset::kSlow;
  o.intra_only = true;  // no P frame: nothing to partition
  auto intra_on = encode_gvid(frames, info, o);
  o.partitions = false;
  auto intra_off = encode_gvid(frames, info, o);
  ASSERT_TRUE(intra_on.is_ok() && intra_off.is_ok());
  EXPECT_TRUE(*intra_on == *intra_off);
}

// Plane level: without RDO (the SATD-based decision) partitions are coded too, and decode to
// the encoder's reconstruction; the macroblocks' motion is exported with partition 0's vector.
TEST(Partitions, PlaneCodingWithoutRdoRoundTrips) {
  const auto frames = video(64, 2);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.qp = 0;
  auto i0 = encode_frame(frames[0], info, o, 0);
  ASSERT_TRUE(i0.is_ok());
  auto p1 = encode_frame(frames[1], info, o, 1, &i0->planes);  // its planes as a source
  ASSERT_TRUE(p1.is_ok());
  for (bool rdo : {false, true})
    for (int subpel : {0, 4}) {
      PlaneCodingParams p;
      p.qp_prime = 48;
      p.partitions = true;
      p.rdo = rdo;
      p.subpel = subpel;
      p.max_transform = 16;
      p.inter_decimation = true;
      const SamplePlane& ref = i0->planes[0];
      const PlaneEncodeResult r = encode_plane(p1->planes[0], p, &ref);
      EXPECT_GT(r.stats.partition_mbs[1] + r.stats.partition_mbs[2] + r.stats.partition_mbs[3], 0)
          << rdo << subpel;
      MotionField motion;
      auto d = decode_plane(r.bytes, 64, 64, p, &ref, nullptr, &motion);
      ASSERT_TRUE(d.is_ok()) << d.status().message();
      EXPECT_TRUE(d->samples == r.reconstruction.samples) << rdo << subpel;
      EXPECT_TRUE(motion.mv_x == r.motion.mv_x && motion.mv_y == r.motion.mv_y);
    }
}

// The partition search finds a block's displacement from a start beside it, to the quarter
// sample, and keeps the start when the predictor's bits outweigh a small distortion gain.
TEST(Partitions, SearchFindsTheDisplacementOfAPartition) {
  SamplePlane ref;
  ref.width = ref.height = 64;
  ref.samples.resize(64 * 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      ref.samples[y * 64 + x] = static_cast<uint16_t>(20000 + 3000 * std::sin(x * 0.31) +
                                                      2500 * std::cos(y * 0.23 + x * 0.05));
  const InterpolatedReference interp(ref, 16, 12);
  // The source's 16x8 block at (24, 16) is the reference displaced by (+2.25, -1.5) samples:
  // the quarter-sample prediction at vector (9, -6) in quarter units.
  SamplePlane src = ref;
  int32_t pred[128];
  interp.predict(24, 16, 16, 8, 9, -6, true, pred);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x)
      src.samples[(16 + y) * 64 + 24 + x] = static_cast<uint16_t>(pred[y * 16 + x]);
  PartitionSearchParams params;
  params.subpel = 4;
  params.lambda = 1.0;
  const int starts[4] = {0, 0, 4, 0};
  const PartitionVector v =
      search_partition_motion(src, interp, 24, 16, 16, 8, 0, 0, starts, params);
  EXPECT_EQ(v.mv_x, 9);
  EXPECT_EQ(v.mv_y, -6);
  EXPECT_DOUBLE_EQ(v.cost, params.lambda * (signed_exp_golomb_bits(9) + signed_exp_golomb_bits(-6)))
      << "zero distortion: the cost is the differences' bits";
  // Whole samples only: the nearest whole-sample vector.
  params.subpel = 0;
  const int whole_starts[2] = {0, 0};
  const PartitionVector w =
      search_partition_motion(src, interp, 24, 16, 16, 8, 0, 0, whole_starts, params);
  EXPECT_EQ(w.mv_x, 2);
  EXPECT_LE(std::abs(w.mv_y + 1), 1);
}

uint8_t flags2_of(const std::string& packet) {
  auto header = format::read_packet_header(packet);
  GVKIT_CHECK(header.is_ok());
  return header->flags2;
}

std::string with_header(const std::string& packet, uint8_t flags2) {
  auto header = format::read_packet_header(packet);
  GVKIT_CHECK(header.is_ok());
  header->flags2 = flags2;
  const size_t old_size = header->header_size;
  return format::write_packet_header(*header) + packet.substr(old_size);
}

// The search's memo of 8x8 distortions: what was stored is found with its value, also among
// keys whose probe chains run into each other; what was not stored is not; nothing after
// clear(); and a full table drops new values instead of returning wrong ones.
TEST(Partitions, DistortionMemoFindsWhatWasStoredOnly) {
  const auto key_of = [](int k) {
    return std::array<int, 5>{k % 3, (k % 40) * 8, (k / 40) * 8, k % 17 - 8, -(k % 11)};
  };
  BlockDistortionMemo memo;
  // A third of the table: every key finds a free slot within its probes.
  for (int k = 0; k < 340; ++k) {
    const auto key = key_of(k);
    ASSERT_EQ(memo.find(key[0], key[1], key[2], key[3], key[4]), -1) << k;
    memo.store(key[0], key[1], key[2], key[3], key[4], 1000 + k);
  }
  for (int k = 0; k < 340; ++k) {
    const auto key = key_of(k);
    EXPECT_EQ(memo.find(key[0], key[1], key[2], key[3], key[4]), 1000 + k) << k;
  }
  for (int k = 340; k < 400; ++k) {
    const auto key = key_of(k);
    EXPECT_EQ(memo.find(key[0], key[1], key[2], key[3], key[4]), -1) << k;
  }
  // Past its capacity: whatever is found is the value stored under that key.
  for (int k = 340; k < 3000; ++k) {
    const auto key = key_of(k);
    memo.store(key[0], key[1], key[2], key[3], key[4], 1000 + k);
  }
  for (int k = 0; k < 3000; ++k) {
    const auto key = key_of(k);
    const int64_t value = memo.find(key[0], key[1], key[2], key[3], key[4]);
    if (value >= 0) {
      EXPECT_EQ(value, 1000 + k) << k;
    }
  }
  memo.clear();
  for (int k = 0; k < 3000; ++k) {
    const auto key = key_of(k);
    ASSERT_EQ(memo.find(key[0], key[1], key[2], key[3], key[4]), -1) << k;
  }
}

TEST(Partitions, CorruptSyntaxIsRejected) {
  const auto frames = video(48, 2);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.preset = Preset::kSlow;
  o.qp = 0;
  o.partitions = true;
  auto i0 = encode_frame(frames[0], info, o, 0);
  ASSERT_TRUE(i0.is_ok());
  EXPECT_EQ(flags2_of(i0->packet) & format::kFrame2Partitions, 0);
  auto p1 = encode_frame(frames[1], info, o, 1, &i0->planes);
  ASSERT_TRUE(p1.is_ok());
  ASSERT_NE(flags2_of(p1->packet) & format::kFrame2Partitions, 0);
  ASSERT_TRUE(decode_frame_packet(p1->packet, info, 1, &i0->planes).is_ok());
  // Bit 5 in an intra frame.
  auto r = decode_frame_packet(
      with_header(i0->packet,
                  static_cast<uint8_t>(flags2_of(i0->packet) | format::kFrame2Partitions)),
      info, 0);
  ASSERT_FALSE(r.is_ok());
  EXPECT_NE(r.status().message().find("inter partitions outside a P frame"), std::string::npos)
      << r.status().message();
  // Flags2 bit 7 (temporal contexts) next to cross-plane contexts is rejected.
  r = decode_frame_packet(
      with_header(p1->packet,
                  static_cast<uint8_t>(flags2_of(p1->packet) | format::kFrame2TemporalContexts |
                                       format::kFrame2CrossPlaneContexts)),
      info, 1, &i0->planes);
  ASSERT_FALSE(r.is_ok());
  EXPECT_NE(r.status().message().find("temporal contexts with cross-plane contexts"),
            std::string::npos)
      << r.status().message();

  // Plane level: one macroblock coded 16x8 whose first partition's vector difference (70
  // samples) leaves the vector range.
  SamplePlane ref;
  ref.width = ref.height = 16;
  ref.samples.assign(256, 1000);
  PlaneCodingParams p;
  p.bit_depth = 16;
  p.qp_prime = 48;
  p.partitions = true;
  CabacEncoder enc;
  CabacContext is_inter, skip, mvd_zero;
  CabacContext bin1{15, 0}, bin2{0, 0};  // the partition contexts' initial states (4.11)
  enc.encode(is_inter, 1);
  enc.encode(skip, 0);
  enc.encode(bin1, 1);  // 16x8 or 8x16
  enc.encode(bin2, 1);  // 16x8
  enc.encode(mvd_zero, 1);
  enc.encode_bypass(0);  // positive
  uint32_t v = 70 - 1;
  int k = 0;
  while (v >= (1u << k)) {
    enc.encode_bypass(1);
    v -= 1u << k;
    ++k;
  }
  enc.encode_bypass(0);
  while (k--) enc.encode_bypass((v >> k) & 1);
  for (int i = 0; i < 64; ++i) enc.encode_bypass(0);
  enc.encode_terminate(1);
  const std::string bytes = enc.finish();
  auto plane = decode_plane(bytes, 16, 16, p, &ref);
  ASSERT_FALSE(plane.is_ok());
  EXPECT_NE(plane.status().message().find("motion vector of partition 0 out of range"),
            std::string::npos)
      << plane.status().message();
  EXPECT_NE(plane.status().message().find("macroblock (0, 0)"), std::string::npos)
      << plane.status().message();
  // Without the tool the same bins read as a 16x16 macroblock (no partition type): the stream
  // then decodes differently or fails, but never as partitions.
  p.partitions = false;
  auto plain = decode_plane(bytes, 16, 16, p, &ref);
  if (!plain.is_ok()) {
    EXPECT_EQ(plain.status().message().find("partition"), std::string::npos)
        << plain.status().message();
  }
}

}  // namespace
}  // namespace gvkit::codec
