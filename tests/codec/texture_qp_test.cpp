// The texture plane's QP (EncoderOptions::texture_qp, coded as the fourth plane QP offset of
// format 2.0, docs/bitstream.md 2.1): the geometry is coded the same whatever the texture's QP,
// a coarser texture costs fewer bytes within its quantizer's error, and a decoder rejects an
// offset out of range naming it.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "packet_surgery.hpp"

namespace gvkit::codec {
namespace {

// An analytic video with a smooth texture (a gradient with a soft spot).
std::vector<GeometryImage> textured_video(int size, int frames) {
  testing::GeometryVideoOptions o;
  o.size = size;
  o.frames = frames;
  std::vector<GeometryImage> video = testing::make_analytic_video(o);
  for (size_t f = 0; f < video.size(); ++f) {
    cv::Mat t(size, size, CV_32F);
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const double dx = x - size * 0.4 - f, dy = y - size * 0.5;
        t.at<float>(y, x) = static_cast<float>(
            0.3 + 0.4 * x / size + 0.25 * std::exp(-(dx * dx + dy * dy) / (0.02 * size * size)));
      }
    video[f].texture = t;
  }
  return video;
}

struct Decoded {
  std::vector<GeometryImage> frames;
  size_t bytes = 0;
};

Decoded encode_decode(const std::vector<GeometryImage>& video, const SequenceInfo& info,
                      const EncoderOptions& o) {
  auto bytes = encode_gvid(video, info, o);
  GVKIT_CHECK(bytes.is_ok(), bytes.status().message());
  auto reader = GvidReader::open_memory(*bytes, "texture.gvid").value();
  Decoded d;
  d.bytes = bytes->size();
  for (int64_t f = 0; f < reader->frame_count(); ++f)
    d.frames.push_back(reader->decode_frame(f).value());
  return d;
}

// Largest |decoded - input| of the texture in 8-bit units.
double texture_max_error(const std::vector<GeometryImage>& in,
                         const std::vector<GeometryImage>& out) {
  double worst = 0;
  for (size_t f = 0; f < in.size(); ++f)
    for (int y = 0; y < in[f].texture.rows; ++y)
      for (int x = 0; x < in[f].texture.cols; ++x)
        worst = std::max(worst, std::abs(255.0 * (in[f].texture.at<float>(y, x) -
                                                  out[f].texture.at<float>(y, x))));
  return worst;
}

TEST(TextureQp, GeometryIsCodedAlikeAndTheTextureFollowsItsQp) {
  const auto video = textured_video(48, 6);
  const SequenceInfo info = testing::info_for(video);
  ASSERT_TRUE(info.has_texture);
  EncoderOptions o;
  o.qp = 0;
  o.preset = Preset::kFast;
  o.texture_qp = -1;  // the frame QP (0): the texture finely quantized
  const Decoded fine = encode_decode(video, info, o);
  o.texture_qp = 36;
  const Decoded coarse = encode_decode(video, info, o);
  ASSERT_EQ(fine.frames.size(), video.size());
  ASSERT_EQ(coarse.frames.size(), video.size());
  for (size_t f = 0; f < video.size(); ++f)
    EXPECT_TRUE(testing::same_samples(fine.frames[f].xyz_mm, coarse.frames[f].xyz_mm))
        << "frame " << f << ": the geometry depends on the texture's QP";
  EXPECT_LT(coarse.bytes, fine.bytes);
  const double fine_error = texture_max_error(video, fine.frames);
  const double coarse_error = texture_max_error(video, coarse.frames);
  EXPECT_LT(fine_error, coarse_error);
  // QP 36 (and 40, 42 in P and B frames): a step of 40-80 8-bit units; the smooth texture stays
  // well within a step.
  EXPECT_LT(coarse_error, 40.0);
}

TEST(TextureQp, OutOfRangeOffsetsAndOptionsAreRejected) {
  const auto video = textured_video(32, 1);
  const SequenceInfo info = testing::info_for(video);
  EncoderOptions o;
  o.qp = 0;
  o.texture_qp = 30;
  o.intra_only = true;
  auto bytes = encode_gvid(video, info, o);
  ASSERT_TRUE(bytes.is_ok());
  const std::string header = format::write_file_header(info);
  const std::string packet = testing::first_packet(*bytes, header.size());
  std::string payload = testing::packet_payload(packet);
  // Plane count byte (4 planes), then the four offsets: X, Y, Z 0 and T 30.
  ASSERT_EQ(static_cast<uint8_t>(payload[0]) & 0x0f, 4);
  ASSERT_EQ(static_cast<int8_t>(payload[4]), 30);
  ASSERT_TRUE(decode_frame_packet(packet, info, 0).is_ok());
  payload[4] = static_cast<char>(int8_t{120});
  const auto bad = decode_frame_packet(testing::with_payload(packet, payload), info, 0);
  ASSERT_FALSE(bad.is_ok());
  EXPECT_NE(bad.status().message().find("texture QP offset"), std::string::npos)
      << bad.status().message();

  EncoderOptions wrong;
  wrong.texture_qp = 52;
  EXPECT_NE(wrong.check().message().find("texture QP"), std::string::npos);
}

}  // namespace
}  // namespace gvkit::codec
