// Larger transforms (flags2 bit 2, docs/bitstream.md 4.8): the 16x16 matrix is HEVC's (within
// rounding of 64 sqrt(2) cos), the butterfly transforms equal the matrix products bit for bit,
// the forward transform is 2^8 x the orthonormal DCT, quantization has the 4x4 path's step
// (reconstruction errors match statistically; flat and gradient blocks round-trip within a
// step); planes and streams coded with 8x8 / 16x16 residuals decode to the encoder's
// reconstruction bit for bit (I, P and B, both presets), smooth planes take the larger
// transforms and get cheaper, and bad frame syntax is rejected with a message.
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "forward_transform16x16_simd.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/crc32.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/plane_coding.hpp"
#include "gvkit/codec/transform.hpp"
#include "gvkit/codec/transform16x16.hpp"
#include "gvkit/core/atomic_file.hpp"
#include "support/test_support.hpp"

namespace gvkit::codec {
namespace {

double dct_basis(int k, int n) {
  const double a = k == 0 ? std::sqrt(1.0 / 16) : std::sqrt(2.0 / 16);
  return a * std::cos((2 * n + 1) * k * M_PI / 32);
}

TEST(Transform16x16, MatrixIsTheScaledDctWithinRounding) {
  for (int k = 0; k < 16; ++k)
    for (int n = 0; n < 16; ++n)
      EXPECT_NEAR(kTransform16[k][n], 256 * dct_basis(k, n), 1.6) << k << ", " << n;
  // Rows nearly orthogonal, of norm ~256.
  for (int a = 0; a < 16; ++a)
    for (int b = 0; b < 16; ++b) {
      int64_t dot = 0;
      for (int n = 0; n < 16; ++n) dot += int64_t{kTransform16[a][n]} * kTransform16[b][n];
      if (a == b)
        EXPECT_NEAR(static_cast<double>(dot), 65536.0, 65536.0 * 0.01) << a;
      else
        EXPECT_LT(std::abs(dot), 200) << a << ", " << b;
    }
}

TEST(Transform16x16, ButterfliesEqualTheMatrixProducts) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> full(-(1 << 17) + 1, (1 << 17) - 1), small(-40, 40);
  for (int t = 0; t < 60; ++t) {
    int32_t r[256], c[256], c_ref[256];
    for (int& v : r) v = t % 2 ? full(rng) : small(rng);
    if (t == 0)
      for (int& v : r) v = (1 << 17) - 1;
    forward_transform16x16(r, c);
    forward_transform16x16_reference(r, c_ref);
    ASSERT_EQ(std::memcmp(c, c_ref, sizeof c), 0) << "forward, trial " << t;
    int64_t d[256];
    for (int i = 0; i < 256; ++i) d[i] = t % 3 == 2 ? int64_t{full(rng)} << 20 : c[i];
    int32_t x[256], x_ref[256];
    inverse_transform16x16(d, x);
    inverse_transform16x16_reference(d, x_ref);
    ASSERT_EQ(std::memcmp(x, x_ref, sizeof x), 0) << "inverse, trial " << t;
  }
}

// The 32-bit forward transform (portable and AVX2) against the reference, up to the largest
// input it takes: random blocks, and the sign patterns that drive every basis function's sum to
// its extreme (|r| = the bound, signs following a row and a column of the matrix).
TEST(Transform16x16, The32BitForwardPathsEqualTheReferenceUpToTheirBound) {
  constexpr int32_t kMax = detail::kForward16x16MaxInput32;
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> u(-kMax, kMax);
  std::vector<std::array<int32_t, 256>> blocks;
  for (int t = 0; t < 40; ++t) {
    std::array<int32_t, 256> r;
    for (int32_t& v : r) v = u(rng);
    blocks.push_back(r);
  }
  for (int k = 0; k < 16; ++k)
    for (int l = 0; l < 16; ++l) {
      std::array<int32_t, 256> r;
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
          r[y * 16 + x] = (kTransform16[k][x] < 0) == (kTransform16[l][y] < 0) ? kMax : -kMax;
      blocks.push_back(r);
    }
  for (const auto& r : blocks) {
    ASSERT_TRUE(detail::forward_transform16x16_fits_32(r.data()));
    int32_t c_ref[256], c32[256], c_avx2[256], c[256];
    forward_transform16x16_reference(r.data(), c_ref);
    detail::forward_transform16x16_32(r.data(), c32);
    detail::forward_transform16x16_32_avx2(r.data(), c_avx2);
    forward_transform16x16(r.data(), c);
    ASSERT_EQ(std::memcmp(c32, c_ref, sizeof c), 0);
    ASSERT_EQ(std::memcmp(c_avx2, c_ref, sizeof c), 0);
    ASSERT_EQ(std::memcmp(c, c_ref, sizeof c), 0);
  }
  std::array<int32_t, 256> over{};
  over[37] = kMax + 1;
  EXPECT_FALSE(detail::forward_transform16x16_fits_32(over.data()));
}

TEST(Transform16x16, ForwardIsTwoToTheEightTimesTheOrthonormalDct) {
  std::mt19937 rng(6);
  std::uniform_int_distribution<int> u(-60000, 60000);
  double worst = 0;
  for (int t = 0; t < 10; ++t) {
    int32_t r[256], c[256];
    double norm = 0;
    for (int& v : r) {
      v = u(rng);
      norm += static_cast<double>(v) * v;
    }
    norm = std::sqrt(norm);
    forward_transform16x16(r, c);
    for (int k = 0; k < 16; ++k)
      for (int l = 0; l < 16; ++l) {
        double s = 0;
        for (int y = 0; y < 16; ++y)
          for (int x = 0; x < 16; ++x) s += dct_basis(k, y) * dct_basis(l, x) * r[y * 16 + x];
        worst = std::max(worst, std::abs(c[k * 16 + l] / 256.0 - s) / norm);
      }
  }
  // The integer matrix deviates from the DCT by up to 1.4 / 256 per entry: each coefficient is
  // within 1 % of the block's L2 norm.
  EXPECT_LT(worst, 0.01);
}

TEST(Transform16x16, InverseOfForwardIsExactToWithinTheMatrixsNonOrthogonality) {
  // HEVC's 16-point rows are orthogonal only to within 188 / 65536: without quantization the
  // round trip returns the residual to within ~1 % of its RMS (below the quantization error
  // whenever the residual is within a few steps, which is where the encoder picks 16x16).
  std::mt19937 rng(8);
  std::uniform_int_distribution<int> u(-1000, 1000);
  for (int t = 0; t < 20; ++t) {
    int32_t r[256], c[256], out[256];
    int64_t d[256];
    for (int& v : r) v = u(rng);
    forward_transform16x16(r, c);
    for (int i = 0; i < 256; ++i) d[i] = c[i] / 16;  // 16 x the orthonormal coefficient
    inverse_transform16x16(d, out);
    double err = 0, energy = 0;
    for (int i = 0; i < 256; ++i) {
      err += static_cast<double>(out[i] - r[i]) * (out[i] - r[i]);
      energy += static_cast<double>(r[i]) * r[i];
    }
    EXPECT_LT(std::sqrt(err / energy), 0.012) << t;
  }
}

TEST(Transform16x16, ZigzagIsAPermutationFollowingTheSmallerScans) {
  std::vector<int> seen(256, 0);
  for (int i = 0; i < 256; ++i) ++seen[kZigzag16x16[static_cast<size_t>(i)]];
  for (int v : seen) EXPECT_EQ(v, 1);
  const uint16_t start[6] = {0, 1, 16, 32, 17, 2};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(kZigzag16x16[static_cast<size_t>(i)], start[i]);
  EXPECT_EQ(kZigzag16x16[255], 255);
  // Consecutive positions are neighbours (one step along a row, column or diagonal).
  for (int i = 1; i < 256; ++i) {
    const int a = kZigzag16x16[static_cast<size_t>(i - 1)],
              b = kZigzag16x16[static_cast<size_t>(i)];
    EXPECT_LE(std::abs(a % 16 - b % 16), 1) << i;
    EXPECT_LE(std::abs(a / 16 - b / 16), 1) << i;
  }
}

// Mean squared reconstruction error of random residual blocks of n x n through the n-point
// path (transform, quantize with the intra offset, dequantize, inverse).
double round_trip_mse(int n, int qp, int trials, std::mt19937& rng, int amplitude) {
  std::uniform_int_distribution<int> u(-amplitude, amplitude);
  double sum = 0;
  int count = 0;
  for (int t = 0; t < trials; ++t) {
    int32_t r[256], c[256], levels[256], out[256];
    int64_t d[256];
    for (int i = 0; i < n * n; ++i) r[i] = u(rng);
    if (n == 16) {
      forward_transform16x16(r, c);
      quantize16x16(c, qp, false, levels);
      dequantize16x16(levels, qp, d);
      inverse_transform16x16(d, out);
    } else {
      forward_transform4x4(r, c);
      quantize(4, c, qp, levels);
      dequantize(4, levels, qp, d);
      inverse_transform4x4(d, out);
    }
    for (int i = 0; i < n * n; ++i) {
      sum += static_cast<double>(out[i] - r[i]) * (out[i] - r[i]);
      ++count;
    }
  }
  return sum / count;
}

TEST(Transform16x16, QuantizerStepMatchesTheFourByFourPath) {
  std::mt19937 rng(7);
  for (int qp : {12, 30, 47, 60, 75, 90}) {
    const double step = quantizer_step(qp);
    // Residuals of a few steps (what prediction leaves): the error is the quantizer's, ~step^2
    // / 12 (a little more with the 1/3 rounding offset), the same for both sizes.
    const int amplitude = static_cast<int>(std::min(6.0 * step, 120000.0));
    const double mse16 = round_trip_mse(16, qp, 200, rng, amplitude);
    const double mse4 = round_trip_mse(4, qp, 3200, rng, amplitude);
    SCOPED_TRACE("qp' " + std::to_string(qp));
    EXPECT_GT(mse16 / mse4, 0.85);
    EXPECT_LT(mse16 / mse4, 1.15);
    EXPECT_GT(mse16, step * step / 12 * 0.9);
    EXPECT_LT(mse16, step * step / 12 * 1.6);
  }
}

TEST(Transform16x16, FlatAndGradientBlocksRoundTripWithinTheStep) {
  for (int qp : {0, 20, 48, 70}) {
    const double step = quantizer_step(qp);
    for (int kind = 0; kind < 3; ++kind) {
      int32_t r[256], c[256], levels[256], out[256];
      int64_t d[256];
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
          r[y * 16 + x] = kind == 0 ? 5000 : (kind == 1 ? 37 * x - 11 * y : 3 * x * y - 300);
      forward_transform16x16(r, c);
      quantize16x16(c, qp, false, levels);
      dequantize16x16(levels, qp, d);
      inverse_transform16x16(d, out);
      double worst = 0, sum = 0;
      for (int i = 0; i < 256; ++i) {
        worst = std::max(worst, std::abs(static_cast<double>(out[i] - r[i])));
        sum += static_cast<double>(out[i] - r[i]) * (out[i] - r[i]);
      }
      SCOPED_TRACE("qp' " + std::to_string(qp) + " kind " + std::to_string(kind));
      if (kind == 0) {
        EXPECT_LE(worst, std::max(1.0, step));
      }
      EXPECT_LE(std::sqrt(sum / 256), std::max(1.0, step));
    }
  }
}

// A smooth 16-bit plane (a quadratic bump with a little texture), shifted by (dx, dy).
SamplePlane smooth_plane(int size, double dx, double dy, int noise_seed) {
  SamplePlane p;
  p.width = p.height = size;
  p.samples.resize(static_cast<size_t>(size) * size);
  std::mt19937 rng(noise_seed);
  std::uniform_int_distribution<int> noise(-12, 12);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double u = (x + dx) / size - 0.5, v = (y + dy) / size - 0.45;
      const double value = 30000 + 20000 * (u * u + 0.7 * v * v) + 3000 * std::sin(5 * u + 2 * v);
      p.at(x, y) = static_cast<uint16_t>(std::clamp(value + noise(rng), 0.0, 65535.0));
    }
  return p;
}

TEST(LargeTransforms, PlanesDecodeToTheEncodersReconstructionAndTakeTheLargerSizes) {
  const SamplePlane ref0 = smooth_plane(64, 0, 0, 1), cur = smooth_plane(64, 1.3, 0.6, 2),
                    ref1 = smooth_plane(64, 2.4, 1.1, 3);
  for (const bool rdo : {false, true})
    for (int qp : {24, 48}) {
      int64_t uses8 = 0, uses16 = 0;
      for (int kind = 0; kind < 3; ++kind) {
        size_t bytes[3] = {};
        for (const int max_transform : {4, 8, 16}) {
          SCOPED_TRACE(std::string(rdo ? "slow" : "fast") + " qp' " + std::to_string(qp) +
                       " kind " + std::to_string(kind) + " max " + std::to_string(max_transform));
          PlaneCodingParams p;
          p.qp_prime = qp;
          p.rdo = rdo;
          p.allow_8x8 = rdo;
          p.subpel = 4;
          p.inter_decimation = true;
          p.max_transform = max_transform;
          const PlaneEncodeResult enc = kind == 0   ? encode_plane(cur, p)
                                        : kind == 1 ? encode_plane(cur, p, &ref0)
                                                    : encode_b_plane(cur, p, ref0, ref1);
          auto dec = kind == 2 ? decode_b_plane(enc.bytes, 64, 64, p, ref0, ref1)
                               : decode_plane(enc.bytes, 64, 64, p, kind == 1 ? &ref0 : nullptr);
          ASSERT_TRUE(dec.is_ok()) << dec.status().message();
          EXPECT_EQ(dec->samples, enc.reconstruction.samples);
          if (max_transform == 4) {
            EXPECT_EQ(enc.stats.transform8_mbs + enc.stats.transform16_mbs, 0);
          } else {
            uses8 += enc.stats.transform8_mbs;
            uses16 += enc.stats.transform16_mbs;
          }
          if (max_transform == 8) {
            EXPECT_EQ(enc.stats.transform16_mbs, 0);
          }
          bytes[max_transform / 8] = enc.bytes.size();
          // Decoded with the wrong max transform, the segment is not the same plane.
          if (max_transform == 16 && enc.stats.transform16_mbs > 0) {
            PlaneCodingParams wrong = p;
            wrong.max_transform = 4;
            auto other = kind == 2
                             ? decode_b_plane(enc.bytes, 64, 64, wrong, ref0, ref1)
                             : decode_plane(enc.bytes, 64, 64, wrong, kind == 1 ? &ref0 : nullptr);
            EXPECT_TRUE(!other.is_ok() || other->samples != enc.reconstruction.samples);
          }
        }
        // The slow preset's decision is a rate-distortion one: never much dearer.
        if (rdo) {
          EXPECT_LT(bytes[2], bytes[0] * 1.03 + 16) << "kind " << kind;
        }
      }
      EXPECT_GT(uses8 + uses16, 0);
      EXPECT_GT(uses16, 0);
    }
}

TEST(LargeTransforms, StreamsRoundTripAndSignalTheToolOnlyWhenOn) {
  testing::GeometryVideoOptions vo;
  vo.size = 48;
  vo.frames = 4;
  const auto frames = testing::make_analytic_video(vo);
  auto info = make_sequence_info(frames, 16, 30.0);
  ASSERT_TRUE(info.is_ok());
  for (const Preset preset : {Preset::kFast, Preset::kSlow})
    for (const int max_transform : {4, 8, 16}) {
      SCOPED_TRACE(std::string(preset_name(preset)) + " max " + std::to_string(max_transform));
      EncoderOptions o;
      o.qp = 6;
      o.preset = preset;
      o.intra_period = 3;
      o.max_transform = max_transform;
      o.resolution = Resolution::kFull;
      std::vector<FrameCodingStats> stats;
      auto bytes = encode_gvid(frames, *info, o, &stats);
      ASSERT_TRUE(bytes.is_ok()) << bytes.status().message();
      auto reader = GvidReader::open_memory(*bytes, "t.gvid");
      ASSERT_TRUE(reader.is_ok()) << reader.status().message();
      for (int64_t f = 0; f < (*reader)->frame_count(); ++f)
        EXPECT_EQ(((*reader)->packet_header(f)->flags2 & format::kFrame2LargeTransforms) != 0,
                  max_transform > 4);
      // The writer's reconstruction equals the decoder's output.
      std::vector<GeometryImage> recon;
      {
        testing::TempDir dir;
        auto writer = GvidWriter::create(dir / "t.gvid", *info, o);
        ASSERT_TRUE(writer.is_ok()) << writer.status().message();
        for (const auto& f : frames) {
          auto done = (*writer)->write(f);
          ASSERT_TRUE(done.is_ok());
          for (auto& r : *done) recon.push_back(std::move(r));
        }
        auto rest = (*writer)->finish();
        ASSERT_TRUE(rest.is_ok());
        for (auto& r : *rest) recon.push_back(std::move(r));
      }
      ASSERT_EQ(recon.size(), frames.size());
      for (int f = 0; f < 4; ++f) {
        auto d = (*reader)->decode_frame(f);
        ASSERT_TRUE(d.is_ok()) << d.status().message();
        for (int y = 0; y < d->xyz_mm.rows; ++y)
          ASSERT_EQ(std::memcmp(d->xyz_mm.ptr(y), recon[f].xyz_mm.ptr(y),
                                d->xyz_mm.cols * d->xyz_mm.elemSize()),
                    0)
              << "frame " << f;
      }
      // Lossless: the tool does not apply, whatever the option says.
      EncoderOptions lossless = o;
      lossless.lossless = true;
      auto exact = encode_gvid(frames, *info, lossless);
      ASSERT_TRUE(exact.is_ok());
      auto exact_reader = GvidReader::open_memory(*exact, "l.gvid").value();
      for (int64_t f = 0; f < exact_reader->frame_count(); ++f)
        EXPECT_EQ(exact_reader->packet_header(f)->flags2 & format::kFrame2LargeTransforms, 0);
      if (max_transform == 4) {
        lossless.max_transform = 16;
        EXPECT_TRUE(encode_gvid(frames, *info, lossless).value() == *exact);
      }
    }
}

TEST(LargeTransforms, BadFrameSyntaxIsRejectedWithAMessage) {
  testing::GeometryVideoOptions vo;
  vo.size = 32;
  vo.frames = 1;
  const auto frames = testing::make_analytic_video(vo);
  auto info = make_sequence_info(frames, 16, 30.0);
  ASSERT_TRUE(info.is_ok());
  EncoderOptions o;
  o.qp = 6;
  o.preset = Preset::kFast;
  o.max_transform = 16;
  o.resolution = Resolution::kFull;
  o.deblocking = false;
  o.cross_plane_contexts = false;
  o.cross_plane = false;  // flags2 then holds the larger-transforms bit alone
  auto frame = encode_frame(frames[0], *info, o, 0);
  ASSERT_TRUE(frame.is_ok()) << frame.status().message();
  const std::string& packet = frame->packet;
  ASSERT_TRUE(decode_frame_packet(packet, *info, 0).is_ok());
  auto h = format::read_packet_header(packet);
  ASSERT_TRUE(h.is_ok());
  ASSERT_TRUE(h->flags2 & format::kFrame2LargeTransforms);
  // The max transform byte follows the plane count (no other payload field in this frame).
  const auto with_payload = [&](std::string payload, uint8_t flags, uint8_t flags2) {
    format::PacketHeader g = *h;
    g.flags = flags;
    g.flags2 = flags2;
    g.payload_size = static_cast<uint32_t>(payload.size());
    g.payload_crc = crc32(payload);
    return format::write_packet_header(g) + payload;
  };
  std::string payload = packet.substr(h->header_size);
  ASSERT_EQ(static_cast<uint8_t>(payload[1]), 16);
  for (const uint8_t bad : {0, 4, 9, 32}) {
    std::string p = payload;
    p[1] = static_cast<char>(bad);
    auto d = decode_frame_packet(with_payload(p, h->flags, h->flags2), *info, 0);
    ASSERT_FALSE(d.is_ok()) << int{bad};
    EXPECT_NE(d.status().message().find("max transform missing or not 8 or 16"), std::string::npos)
        << d.status().message();
  }
  auto lossless = decode_frame_packet(
      with_payload(payload, h->flags | format::kFrameLossless | format::kFrameAdaptiveLevels,
                   h->flags2),
      *info, 0);
  ASSERT_FALSE(lossless.is_ok());
  EXPECT_NE(lossless.status().message().find("larger transforms in a lossless frame"),
            std::string::npos)
      << lossless.status().message();
  // Without the bit the byte is read as the first plane's segment size: rejected.
  auto unflagged = decode_frame_packet(
      with_payload(payload, h->flags, h->flags2 & ~format::kFrame2LargeTransforms), *info, 0);
  EXPECT_FALSE(unflagged.is_ok());
  // Flags2 bit 7 (temporal contexts) in this intra frame is rejected.
  auto temporal = decode_frame_packet(with_payload(payload, h->flags, h->flags2 | 128), *info, 0);
  ASSERT_FALSE(temporal.is_ok());
  EXPECT_NE(temporal.status().message().find("temporal contexts in an intra frame"),
            std::string::npos)
      << temporal.status().message();
  // Damage inside the plane segments (CRC fixed): frames or a Status naming the plane.
  std::mt19937 rng(9);
  int failures = 0;
  for (int trial = 0; trial < 150; ++trial) {
    std::string p = payload;
    for (int k = 0; k < 1 + trial % 3; ++k) p[6 + rng() % (p.size() - 6)] ^= 1 << (rng() % 8);
    auto d = decode_frame_packet(with_payload(p, h->flags, h->flags2), *info, 0);
    if (!d.is_ok()) {
      ++failures;
      EXPECT_NE(d.status().message().find("plane"), std::string::npos) << d.status().message();
    }
  }
  EXPECT_GT(failures, 0);
}

TEST(LargeTransforms, OptionsOutOfRangeAreRejectedByName) {
  EncoderOptions o;
  for (const int bad : {0, 2, 6, 32}) {
    o.max_transform = bad;
    const Status s = o.check();
    ASSERT_FALSE(s.is_ok());
    EXPECT_NE(s.message().find("max transform"), std::string::npos) << s.message();
  }
  o.max_transform = 16;
  EXPECT_TRUE(o.check().is_ok());
}

}  // namespace
}  // namespace gvkit::codec
