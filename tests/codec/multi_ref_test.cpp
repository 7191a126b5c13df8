// Multiple reference frames (flags2 bit 1, docs/bitstream.md 4.7). The decoder (GvidReader, in
// display order and by random access) reproduces the encoder's reconstruction exactly in every
// configuration; content that returns after a frame is predicted from two frames back; corrupt
// ref_count syntax is rejected with a message; refs = 1 codes no reference list.
#include <string>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/sequence_encoder.hpp"
#include "packet_surgery.hpp"

namespace gvkit::codec {
namespace {

// The analytic surface moving by (0.75, 0.375) pixels per frame.
std::vector<GeometryImage> video(int size, int frames) {
  testing::GeometryVideoOptions o;
  o.size = size;
  o.frames = frames;
  auto video = testing::make_analytic_video(o);
  testing::move_in_picture(&video, 0.75);
  return video;
}

// Encodes with SequenceEncoder (reconstructions by display index) and with encode_gvid (the
// stream); expects the packets to agree and GvidReader to reproduce every reconstruction, in
// display order and then by random access.
void expect_round_trip(const std::vector<GeometryImage>& frames, const SequenceInfo& info,
                       const EncoderOptions& o, const std::string& what) {
  auto encoder = SequenceEncoder::create(info, o);
  ASSERT_TRUE(encoder.is_ok()) << what;
  std::vector<GeometryImage> recon(frames.size());
  std::string packets;
  const auto keep = [&](std::vector<SequenceFrame> done) {
    for (SequenceFrame& f : done) {
      packets += f.packet;
      recon[f.number] = std::move(f.reconstruction);
    }
  };
  for (const GeometryImage& f : frames) {
    auto done = (*encoder)->push(f);
    ASSERT_TRUE(done.is_ok()) << what << ": " << done.status().message();
    keep(std::move(done).value());
  }
  auto rest = (*encoder)->flush();
  ASSERT_TRUE(rest.is_ok()) << what;
  keep(std::move(rest).value());
  auto bytes = encode_gvid(frames, info, o);
  ASSERT_TRUE(bytes.is_ok()) << what << ": " << bytes.status().message();
  const std::string header = format::write_file_header(info, o.resolved_profile());
  ASSERT_EQ(bytes->substr(header.size(), packets.size()), packets) << what;
  auto reader = GvidReader::open_memory(*bytes, what);
  ASSERT_TRUE(reader.is_ok()) << what << ": " << reader.status().message();
  int multi = 0;
  for (int64_t f = 0; f < (*reader)->frame_count(); ++f) {
    if ((*reader)->frame_references(f) > 1 &&
        (*reader)->frame_type(f) == format::FrameType::kPredicted)
      ++multi;
    auto image = (*reader)->decode_frame(f);
    ASSERT_TRUE(image.is_ok()) << what << " frame " << f << ": " << image.status().message();
    ASSERT_TRUE(testing::same_samples(image->xyz_mm, recon[f].xyz_mm)) << what << " frame " << f;
    ASSERT_TRUE(testing::same_samples(image->texture, recon[f].texture))
        << what << " texture " << f;
  }
  EXPECT_GT(multi, 0) << what << ": no P frame with several references";
  auto again = GvidReader::open_memory(*bytes, what);
  ASSERT_TRUE(again.is_ok());
  for (int64_t f : {7, 3, 6, 0, 5, 1, 4, 2}) {
    if (f >= (*again)->frame_count()) continue;
    auto image = (*again)->decode_frame(f);
    ASSERT_TRUE(image.is_ok()) << what << " frame " << f << ": " << image.status().message();
    ASSERT_TRUE(testing::same_samples(image->xyz_mm, recon[f].xyz_mm))
        << what << " random frame " << f;
    ASSERT_TRUE(testing::same_samples(image->texture, recon[f].texture))
        << what << " random texture " << f;
  }
}

TEST(MultiRef, DecoderReproducesTheEncoderInEveryConfiguration) {
  const auto frames = video(48, 8);
  const SequenceInfo info = testing::info_for(frames);
  for (Preset preset : {Preset::kFast, Preset::kSlow})
    for (int mode = 0; mode < 3; ++mode)  // lossy, lossless, near-lossless
      for (int refs : {2, 5})
        for (int bframes : {0, 1})
          for (bool shared : {false, true}) {
            if (shared && bframes) continue;
            EncoderOptions o;
            o.preset = preset;
            o.qp = 0;
            o.lossless = mode == 1;
            o.max_error_mm = mode == 2 ? 0.05 : 0;
            o.refs = refs;
            o.bframes = bframes;
            o.shared_motion = shared;
            o.joint_motion_search = shared;
            o.value_prediction = refs == 5 ? ValuePrediction::kAffine : ValuePrediction::kNone;
            const std::string what = std::string(preset_name(preset)) + " mode " +
                                     std::to_string(mode) + " refs " + std::to_string(refs) +
                                     " bframes " + std::to_string(bframes) +
                                     (shared ? " shared" : "");
            expect_round_trip(frames, info, o, what);
          }
}

// A sequence with a texture plane: T predicts from its references like X, Y and Z.
TEST(MultiRef, TexturePlaneRoundTrips) {
  auto frames = video(48, 6);
  for (size_t i = 0; i < frames.size(); ++i) {
    GeometryImage& f = frames[i];
    f.texture.create(f.xyz_mm.size(), CV_32F);
    for (int y = 0; y < f.texture.rows; ++y)
      for (int x = 0; x < f.texture.cols; ++x)
        f.texture.at<float>(y, x) =
            ((x * 7 + y * 3 + static_cast<int>(i) * (i % 2 ? 40 : 2)) % 256) / 255.0f;
  }
  const SequenceInfo info = testing::info_for(frames);
  ASSERT_TRUE(info.has_texture);
  EncoderOptions o;
  o.preset = Preset::kSlow;
  o.qp = 0;
  o.bframes = 0;
  o.refs = 4;
  expect_round_trip(frames, info, o, "texture refs 4");
}

// Frames alternate between two shapes: with two references each P frame finds its content two
// frames back and costs far less than with one.
TEST(MultiRef, ReturningContentIsPredictedFromTwoFramesBack) {
  auto frames = video(48, 8);
  const auto other = video(48, 1);
  for (size_t f = 0; f < frames.size(); ++f) {
    if (f % 2 == 0) {
      frames[f].xyz_mm = frames[0].xyz_mm.clone();
    } else {
      cv::Mat flipped;
      cv::flip(other[0].xyz_mm, flipped, 1);
      frames[f].xyz_mm = flipped;
    }
  }
  const SequenceInfo info = testing::info_for(frames);
  for (Preset preset : {Preset::kFast, Preset::kSlow}) {
    EncoderOptions o;
    o.preset = preset;
    o.qp = 6;
    o.bframes = 0;
    o.refs = 1;
    auto one = encode_gvid(frames, info, o);
    o.refs = 2;
    auto two = encode_gvid(frames, info, o);
    ASSERT_TRUE(one.is_ok() && two.is_ok());
    EXPECT_LT(two->size() * 10, one->size() * 6) << preset_name(preset);  // I frame included
    expect_round_trip(frames, info, o, std::string("alternating ") + preset_name(preset));
  }
}

TEST(MultiRef, CorruptSyntaxIsRejected) {
  const auto frames = video(48, 3);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.preset = Preset::kFast;
  o.qp = 0;
  o.refs = 2;
  o.max_transform = 4;  // flags2 then holds the multiple-reference bit alone
  o.cross_plane = false;
  o.cross_plane_contexts = false;
  o.temporal_contexts = false;
  o.deblocking = false;
  o.resolution = Resolution::kFull;
  auto i0 = encode_frame(frames[0], info, o, 0);
  ASSERT_TRUE(i0.is_ok());
  auto p1 = encode_frame(frames[1], info, o, 1, &i0->planes);
  ASSERT_TRUE(p1.is_ok());
  const std::vector<const std::vector<SamplePlane>*> older = {&i0->planes};
  auto p2 = encode_frame(frames[2], info, o, 2, &p1->planes, nullptr, &older);
  ASSERT_TRUE(p2.is_ok());
  // One anchor since the intra frame: no reference list.
  EXPECT_EQ(format::read_packet_header(p1->packet)->flags2, 0);
  ASSERT_EQ(format::read_packet_header(p2->packet)->flags2, format::kFrame2MultiRef);
  ASSERT_EQ(packet_reference_count(p2->packet).value(), 2);
  auto good = decode_frame_packet(p2->packet, info, 2, &p1->planes, nullptr, nullptr, &older);
  ASSERT_TRUE(good.is_ok()) << good.status().message();
  const auto expect_error = [&](const std::string& packet,
                                const std::vector<const std::vector<SamplePlane>*>* refs,
                                const std::string& message) {
    auto r = decode_frame_packet(packet, info, 2, &p1->planes, nullptr, nullptr, refs);
    ASSERT_FALSE(r.is_ok()) << message;
    EXPECT_NE(r.status().message().find(message), std::string::npos) << r.status().message();
  };
  expect_error(p2->packet, nullptr,
               "ref_count 2 names more reference frames than the 1 anchor frames since the last "
               "intra frame");
  // The payload: plane count, then ref_count (no other optional fields in this frame).
  const std::string payload = testing::packet_payload(p2->packet);
  for (int bad : {0, 1, 6, 255}) {
    std::string p = payload;
    p[1] = static_cast<char>(bad);
    expect_error(testing::with_payload(p2->packet, p), &older,
                 "ref_count " + std::to_string(bad) + " out of range (2..5)");
  }
  std::string three = payload;
  three[1] = 3;
  expect_error(testing::with_payload(p2->packet, three), &older,
               "ref_count 3 names more reference frames");
  expect_error(testing::with_payload(p2->packet, payload.substr(0, 1)), &older,
               "ref_count missing");
  auto header = format::read_packet_header(i0->packet);
  ASSERT_TRUE(header.is_ok());
  header->flags2 = format::kFrame2MultiRef;
  auto r = decode_frame_packet(
      format::write_packet_header(*header) + i0->packet.substr(header->header_size), info, 0);
  ASSERT_FALSE(r.is_ok());
  EXPECT_NE(r.status().message().find("multiple reference frames in an intra frame"),
            std::string::npos)
      << r.status().message();
  // A damaged macroblock layer fails naming the plane (no crash with the reference list).
  std::string cut = payload;
  cut[2 + 4 + 3] ^= 0x5a;
  auto damaged = decode_frame_packet(testing::with_payload(p2->packet, cut), info, 2, &p1->planes,
                                     nullptr, nullptr, &older);
  if (!damaged.is_ok()) {
    EXPECT_NE(damaged.status().message().find("plane"), std::string::npos)
        << damaged.status().message();
  }
}

TEST(MultiRef, OneReferenceCodesNoReferenceListAndOptionsAreChecked) {
  const auto frames = video(48, 4);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.preset = Preset::kFast;
  o.bframes = 0;
  EXPECT_EQ(o.reference_frames(), 3);  // automatic: 3 in lossy streams
  o.refs = 1;
  auto one = encode_gvid(frames, info, o);
  ASSERT_TRUE(one.is_ok());
  o.refs = 3;
  auto three = encode_gvid(frames, info, o);
  ASSERT_TRUE(three.is_ok());
  EXPECT_NE(*one, *three);
  // The first P frame has one anchor before it: it is the same packet as with one reference.
  auto r1 = GvidReader::open_memory(*one, "one"), r3 = GvidReader::open_memory(*three, "three");
  ASSERT_TRUE(r1.is_ok() && r3.is_ok());
  EXPECT_EQ((*r1)->frame_bits(1), (*r3)->frame_bits(1));
  EXPECT_EQ((*r3)->frame_references(1), 1);
  EXPECT_EQ((*r3)->frame_references(3), 3);
  for (int64_t f = 0; f < (*r1)->frame_count(); ++f) {
    EXPECT_EQ((*r1)->frame_references(f), f == 0 ? 0 : 1) << f;
    EXPECT_EQ((*r1)->packet_header(f)->flags2 & format::kFrame2MultiRef, 0) << f;
  }
  EncoderOptions automatic;
  automatic.lossless = true;
  EXPECT_EQ(automatic.reference_frames(), 1);  // 1 in lossless and near-lossless streams
  automatic.lossless = false;
  automatic.max_error_mm = 0.1;
  EXPECT_EQ(automatic.reference_frames(), 1);
  for (int bad : {0, -2, 6}) {
    EncoderOptions b;
    b.refs = bad;
    const Status s = b.check();
    ASSERT_FALSE(s.is_ok());
    EXPECT_NE(s.message().find("refs " + std::to_string(bad)), std::string::npos) << s.message();
  }
}

}  // namespace
}  // namespace gvkit::codec
