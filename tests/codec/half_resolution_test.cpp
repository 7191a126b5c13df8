// Half resolution (the packet type byte's bit 4, docs/bitstream.md 2.3): the
// upsampling filter reproduces constant and linear surfaces, the encoder's least-squares halving
// upsamples closer to the frame than a 2x2 mean, the decoder reproduces the encoder in every
// configuration (presets, B frames, references, odd sizes, texture, threads), a B frame whose
// anchors differ in resolution decodes, resolution auto chooses by the content and the rate,
// the ICT face gets cheaper, and inconsistent packets and options are rejected.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/half_resolution.hpp"
#include "packet_surgery.hpp"
#include "support/test_support.hpp"

namespace gvkit::codec {
namespace {

// A plane of w x h samples (padded to 16) of f(x, y) rounded.
template <class F>
SamplePlane plane_of(int w, int h, const F& f) {
  SamplePlane p;
  p.width = (w + 15) / 16 * 16;
  p.height = (h + 15) / 16 * 16;
  p.samples.resize(static_cast<size_t>(p.width) * p.height);
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x)
      p.at(x, y) = static_cast<uint16_t>(std::lround(f(std::min(x, w - 1), std::min(y, h - 1))));
  return p;
}

// Mean squared difference over the first w x h samples.
double mse(const SamplePlane& a, const SamplePlane& b, int w, int h) {
  double sum = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double d = static_cast<double>(a.at(x, y)) - b.at(x, y);
      sum += d * d;
    }
  return sum / (static_cast<double>(w) * h);
}

// Frames whose packets have the half-resolution bit, in decode order.
std::vector<bool> half_packets(const std::string& stream) {
  auto reader = GvidReader::open_memory(stream, "x.gvid").value();
  std::vector<bool> half;
  for (int64_t f = 0; f < reader->frame_count(); ++f)
    half.push_back(reader->packet_header(f)->half_resolution);
  return half;
}

TEST(HalfResolution, UpsamplingKeepsConstantsAndLinearSurfaces) {
  const SamplePlane flat = plane_of(20, 12, [](int, int) { return 40000.0; });
  const SamplePlane up = upsample_half_plane(flat, 40, 24, 16);
  EXPECT_EQ(up.width, 48);
  EXPECT_EQ(up.height, 32);
  for (int y = 0; y < up.height; ++y)
    for (int x = 0; x < up.width; ++x) ASSERT_EQ(up.at(x, y), 40000) << x << "," << y;
  // Half-resolution sample i sits at full-resolution position 2i + 1/2: a linear function of i
  // upsamples to the same function at the pixels (exactly, 1/4 steps of 64 being 16), away from
  // the clamped edges.
  const SamplePlane ramp = plane_of(20, 12, [](int i, int j) { return 1000.0 + 64 * i + 128 * j; });
  const SamplePlane r = upsample_half_plane(ramp, 40, 24, 16);
  for (int y = 4; y < 20; ++y)
    for (int x = 4; x < 36; ++x)
      ASSERT_EQ(r.at(x, y), 1000 + 64 * (x - 0.5) / 2 + 128 * (y - 0.5) / 2) << x << "," << y;
  // Results are clamped to the bit depth.
  const SamplePlane edge = plane_of(8, 8, [](int i, int) { return i < 4 ? 0.0 : 255.0; });
  const SamplePlane e = upsample_half_plane(edge, 16, 16, 8);
  for (uint16_t v : e.samples) ASSERT_LE(v, 255);
}

TEST(HalfResolution, LeastSquaresHalvingUpsamplesCloserThanA2x2Mean) {
  for (const auto& [w, h] : {std::pair{64, 48}, std::pair{33, 17}}) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    const SamplePlane full = plane_of(w, h, [](int x, int y) {
      return 30000 + 9000 * std::sin(0.11 * x) * std::cos(0.07 * y) + 3.0 * x * y;
    });
    const SamplePlane ls = downsample_plane(full, w, h, 16);
    const SamplePlane mean = halve_plane_mean(full, w, h);
    EXPECT_EQ(ls.width, (half_size(w) + 15) / 16 * 16);
    EXPECT_EQ(ls.height, (half_size(h) + 15) / 16 * 16);
    const double e_ls = mse(full, upsample_half_plane(ls, w, h, 16), w, h);
    const double e_mean = mse(full, upsample_half_plane(mean, w, h, 16), w, h);
    EXPECT_LT(e_ls, e_mean);
    EXPECT_LT(std::sqrt(e_ls), 60.0);  // a smooth surface of amplitude 9000 samples
  }
}

TEST(HalfResolution, DecoderReproducesTheEncoderInEveryConfiguration) {
  const auto frames = testing::make_moving_analytic_video(64, 7);
  const SequenceInfo info = testing::info_for(frames);
  auto cases = testing::p_frame_cases();
  EncoderOptions two_b = cases[4].second;
  two_b.bframes = 2;
  cases.push_back({"slow, two B frames", two_b});
  for (auto& [what, o] : cases) {
    SCOPED_TRACE(what);
    if (o.bypass()) continue;  // lossless and max-error coding are at full resolution
    o.resolution = Resolution::kHalf;
    const std::string stream = testing::writer_round_trip(frames, info, o);
    for (const bool half : half_packets(stream)) EXPECT_TRUE(half);
  }
}

TEST(HalfResolution, OddSizesAndTextureRoundTrip) {
  testing::GeometryVideoOptions vo;
  vo.size = 45;
  vo.frames = 4;
  auto frames = testing::make_analytic_video(vo);
  for (auto& f : frames) {  // odd height too, and a smooth texture (the fourth plane, 8 bits)
    f.xyz_mm = f.xyz_mm.rowRange(0, 37).clone();
    f.domain_mask = f.domain_mask.rowRange(0, 37).clone();
    f.texture.create(37, 45, CV_32F);
    for (int y = 0; y < 37; ++y)
      for (int x = 0; x < 45; ++x) f.texture.at<float>(y, x) = 0.2f + 0.01f * x + 0.005f * y;
  }
  const SequenceInfo info = testing::info_for(frames);
  ASSERT_TRUE(info.has_texture);
  EncoderOptions o;
  o.resolution = Resolution::kHalf;
  o.qp = 6;
  o.threads = 2;
  const std::string stream = testing::writer_round_trip(frames, info, o);
  auto reader = GvidReader::open_memory(stream, "x.gvid").value();
  const GeometryImage last = reader->decode_frame(3).value();
  EXPECT_EQ(last.xyz_mm.cols, 45);
  EXPECT_EQ(last.xyz_mm.rows, 37);
  ASSERT_EQ(last.texture.size(), frames[3].texture.size());
  double max_texture_error = 0;
  for (int y = 0; y < 37; ++y)
    for (int x = 0; x < 45; ++x)
      max_texture_error = std::max<double>(
          max_texture_error,
          std::abs(last.texture.at<float>(y, x) - frames[3].texture.at<float>(y, x)));
  EXPECT_LT(max_texture_error, 0.05);  // a linear ramp survives halving and upsampling
}

// Encodes I0 P2 at one resolution and I4 at the other, then B frame 3 (anchors 2 and 4) and
// B frame 1; the decoder reproduces every reconstruction.
TEST(HalfResolution, ABFrameBetweenAnchorsOfBothResolutionsDecodes) {
  const auto frames = testing::make_moving_analytic_video(48, 5);
  const SequenceInfo info = testing::info_for(frames);
  for (const bool first_half : {false, true}) {
    SCOPED_TRACE(first_half ? "half, then full" : "full, then half");
    EncoderOptions a, b;
    a.qp = b.qp = 6;
    a.resolution = first_half ? Resolution::kHalf : Resolution::kFull;
    b.resolution = first_half ? Resolution::kFull : Resolution::kHalf;
    auto i0 = encode_frame(frames[0], info, a, 0).value();
    auto p2 = encode_frame(frames[2], info, a, 2, &i0.planes).value();
    auto i4 = encode_frame(frames[4], info, b, 4).value();
    auto b3 = encode_frame(frames[3], info, a, 3, &p2.planes, &i4.planes).value();
    auto b1 = encode_frame(frames[1], info, a, 1, &i0.planes, &p2.planes).value();
    EXPECT_EQ(p2.planes[0].half_resolution, first_half);
    EXPECT_EQ(i4.planes[0].half_resolution, !first_half);
    EXPECT_EQ(b3.planes[0].half_resolution, first_half);  // the anchor before it decides
    std::vector<SamplePlane> d0, d2, d4;
    const auto same = [](const GeometryImage& x, const EncodedFrame& e) {
      return testing::same_samples(x.xyz_mm, e.reconstruction.xyz_mm);
    };
    EXPECT_TRUE(same(decode_frame_packet(i0.packet, info, 0, nullptr, &d0).value(), i0));
    EXPECT_TRUE(same(decode_frame_packet(p2.packet, info, 2, &d0, &d2).value(), p2));
    EXPECT_TRUE(same(decode_frame_packet(i4.packet, info, 4, nullptr, &d4).value(), i4));
    EXPECT_TRUE(same(decode_frame_packet(b3.packet, info, 3, &d2, nullptr, &d4).value(), b3));
    EXPECT_TRUE(same(decode_frame_packet(b1.packet, info, 1, &d0, nullptr, &d2).value(), b1));
  }
}

// Resolution auto: full resolution where halving loses more than coding (a fine QP, or detail
// at the pixel scale), half where it loses less (a coarse QP on a smooth surface); every frame
// of a group of pictures follows its I frame.
TEST(HalfResolution, AutoChoosesByTheContentAndTheRate) {
  const auto smooth = testing::make_moving_analytic_video(64, 6);
  const SequenceInfo info = testing::info_for(smooth);
  EncoderOptions o;  // kAuto by default
  ASSERT_EQ(o.resolution, Resolution::kAuto);
  o.intra_period = 3;
  o.qp = 24;
  for (const bool half : half_packets(testing::writer_round_trip(smooth, info, o)))
    EXPECT_TRUE(half);
  o.qp = -18;
  for (const bool half : half_packets(testing::writer_round_trip(smooth, info, o)))
    EXPECT_FALSE(half);
  // Pixel-scale detail (a checkerboard of +-2 mm on z) in the first group only.
  auto detailed = smooth;
  for (int f = 0; f < 3; ++f)
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x)
        detailed[f].xyz_mm.at<cv::Vec3f>(y, x)[2] += (x + y) % 2 ? 2 : -2;
  o.qp = 12;
  const std::string stream = testing::writer_round_trip(detailed, info, o);
  auto reader = GvidReader::open_memory(stream, "x.gvid").value();
  ASSERT_EQ(reader->frame_count(), 6);
  for (int64_t f = 0; f < reader->frame_count(); ++f)
    EXPECT_EQ(reader->packet_header(f)->half_resolution,
              reader->packet_header(f)->frame_number >= 3)
        << "packet " << f;
}

// The ICT face (when the shared data is present), slow preset at a low rate: resolution auto
// codes at half resolution, and the stream is smaller at no lower geometry PSNR than a full
// resolution stream of at least its size.
TEST(HalfResolution, MakesTheIctFaceCheaperAtLowRates) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  testing::GeometryVideoOptions vo;
  vo.size = 128;
  vo.frames = 7;
  auto frames = testing::make_ict_face_video(data / "ict-facekit", vo);
  ASSERT_TRUE(frames.is_ok()) << frames.status().message();
  const SequenceInfo info = testing::info_for(*frames);
  EncoderOptions half;
  half.qp = 18;
  EncoderOptions full = half;
  full.resolution = Resolution::kFull;
  const std::string h = testing::writer_round_trip(*frames, info, half);
  for (const bool b : half_packets(h)) EXPECT_TRUE(b);
  // The finest full-resolution stream no larger than the half-resolution one has a lower PSNR.
  for (full.qp = 18; full.qp <= 36; full.qp += 3) {
    const std::string f = testing::writer_round_trip(*frames, info, full);
    if (f.size() > h.size()) continue;
    EXPECT_LT(testing::stream_psnr_db(*frames, info, f), testing::stream_psnr_db(*frames, info, h))
        << "full resolution at qp " << full.qp;
    break;
  }
}

TEST(HalfResolution, InconsistentPacketsAndOptionsAreRejected) {
  const auto frames = testing::make_moving_analytic_video(32, 2);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions o;
  o.qp = 6;
  o.resolution = Resolution::kFull;
  auto i0 = encode_frame(frames[0], info, o, 0).value();
  auto p1 = encode_frame(frames[1], info, o, 1, &i0.planes).value();
  // A P packet claiming half resolution over a full-resolution reference.
  const auto relabel = [](const std::string& packet, bool half, bool lossless) {
    format::PacketHeader h = format::read_packet_header(packet).value();
    h.half_resolution = half;
    if (lossless) h.flags |= format::kFrameLossless;
    return format::write_packet_header(h) + testing::packet_payload(packet);
  };
  std::vector<SamplePlane> d0;
  ASSERT_TRUE(decode_frame_packet(i0.packet, info, 0, nullptr, &d0).is_ok());
  auto bad = decode_frame_packet(relabel(p1.packet, true, false), info, 1, &d0);
  ASSERT_FALSE(bad.is_ok());
  EXPECT_NE(bad.status().message().find("reference frame at full"), std::string::npos)
      << bad.status().message();
  auto lossless = decode_frame_packet(relabel(i0.packet, true, true), info, 0);
  ASSERT_FALSE(lossless.is_ok());
  EXPECT_NE(lossless.status().message().find("half resolution in a lossless frame"),
            std::string::npos)
      << lossless.status().message();
  // The header round trip keeps the bit; other type values stay corrupt.
  format::PacketHeader h;
  h.type = format::FrameType::kPredicted;
  h.half_resolution = true;
  const auto back = format::read_packet_header(format::write_packet_header(h)).value();
  EXPECT_TRUE(back.half_resolution);
  EXPECT_EQ(back.type, format::FrameType::kPredicted);
  // Options: half resolution excludes lossless and max-error coding.
  EncoderOptions lossless_half;
  lossless_half.lossless = true;
  lossless_half.resolution = Resolution::kHalf;
  EXPECT_FALSE(lossless_half.check().is_ok());
  EXPECT_FALSE(parse_resolution("quarter").is_ok());
  EXPECT_EQ(parse_resolution("half").value(), Resolution::kHalf);
}

}  // namespace
}  // namespace gvkit::codec
