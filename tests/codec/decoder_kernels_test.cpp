// The decoder's optimised kernels (AVX2 where the processor has it) return exactly what their
// plain reference versions return, on random input and at the extremes of the sample range:
// the CABAC decoding engine, motion-compensated prediction (every phase, block size and border
// case), the deblocking filter, the clipped store of prediction + residual, the inverse residual
// (dequantization + inverse transform) of sparse, dense, small and huge level blocks,
// half-resolution upsampling and dequantization to millimetres.
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "gvkit/codec/cabac_decoder.hpp"
#include "gvkit/codec/deblocking.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/half_resolution.hpp"
#include "gvkit/codec/inverse_residual.hpp"
#include "gvkit/codec/motion_compensation.hpp"
#include "gvkit/codec/reconstruction_store.hpp"

#include "codec/random_sample_plane.hpp"

namespace gvkit::codec {
namespace {

using testing::random_plane;

int padded(int n) { return (n + 15) / 16 * 16; }

TEST(DecoderKernels, CabacTransitionTableIsCabacUpdate) {
  for (int state = 0; state < 64; ++state)
    for (int mps = 0; mps < 2; ++mps)
      for (int bin = 0; bin < 2; ++bin) {
        CabacContext a{static_cast<uint8_t>(state), static_cast<uint8_t>(mps)};
        cabac_update(a, bin);
        const uint8_t next = kCabacTransition[state][bin != mps];
        EXPECT_EQ(a.state, next & 63) << state << " " << mps << " " << bin;
        EXPECT_EQ(a.mps, mps ^ (next >> 7)) << state << " " << mps << " " << bin;
      }
}

// Random data read as a random mix of context bins (from a few contexts, so that states reach
// both ends), bypass bins and terminations, past the end of the data.
TEST(DecoderKernels, CabacDecoderEqualsTheReference) {
  std::mt19937 rng(10);
  for (int trial = 0; trial < 200; ++trial) {
    std::string data(static_cast<size_t>(rng() % 300), '\0');
    for (char& c : data) c = static_cast<char>(rng() & 0xFF);
    // Skewed data too: long runs of zeros or ones keep the contexts in their confident states.
    if (trial % 3 == 1)
      for (size_t i = 0; i < data.size(); ++i) data[i] = i % 7 ? '\0' : data[i];
    if (trial % 3 == 2)
      for (size_t i = 0; i < data.size(); ++i) data[i] = i % 5 ? '\x7f' : data[i];
    if (!data.empty() && static_cast<uint8_t>(data[0]) == 0xFF) data[0] = '\x7f';  // see header
    CabacDecoder fast(data);
    CabacDecoderReference plain(data);
    CabacContext fast_ctx[4] = {}, plain_ctx[4] = {};
    const int bins = static_cast<int>(data.size()) * 12 + 40;
    for (int i = 0; i < bins; ++i) {
      const uint32_t what = rng() % 16;
      if (what == 0) {
        ASSERT_EQ(fast.decode_bypass(), plain.decode_bypass()) << trial << " bin " << i;
      } else if (what == 1 && i % 97 == 0) {
        const int t = fast.decode_terminate();
        ASSERT_EQ(t, plain.decode_terminate()) << trial << " bin " << i;
        if (t) break;
      } else {
        const int c = static_cast<int>(what % 4);
        ASSERT_EQ(fast.decode(fast_ctx[c]), plain.decode(plain_ctx[c])) << trial << " bin " << i;
        ASSERT_EQ(fast_ctx[c].state, plain_ctx[c].state);
        ASSERT_EQ(fast_ctx[c].mps, plain_ctx[c].mps);
      }
      ASSERT_EQ(fast.overrun(), plain.overrun()) << trial << " bin " << i;
    }
  }
}

TEST(DecoderKernels, InverseResidualEqualsTheReference) {
  std::mt19937 rng(13);
  for (int trial = 0; trial < 3000; ++trial) {
    const int n = trial % 5 == 0 ? 4 : (trial % 5 == 1 ? 8 : 16);
    const int qp = static_cast<int>(rng() % 100);
    int32_t levels[256] = {};
    // Levels in a corner of the block (decoded blocks), anywhere, or everywhere; magnitudes from
    // +-1 to the decoder's limit (2^24), so that both paths and the bound between them are hit.
    const int reach = 1 + static_cast<int>(rng() % n), count = static_cast<int>(rng() % 40);
    const int magnitude_bits = static_cast<int>(rng() % 25);
    std::uniform_int_distribution<int> value(-(1 << magnitude_bits), 1 << magnitude_bits);
    for (int i = 0; i < (trial % 7 == 0 ? n * n : count); ++i) {
      const int x = static_cast<int>(rng() % (trial % 3 ? reach : n)),
                y = static_cast<int>(rng() % (trial % 3 ? reach : n));
      levels[y * n + x] = value(rng);
    }
    if (trial % 50 == 3) levels[static_cast<int>(rng() % (n * n))] = (1 << 24) - 1;
    int32_t fast[256], plain[256];
    inverse_residual(n, levels, qp, fast);
    inverse_residual_reference(n, levels, qp, plain);
    ASSERT_EQ(0, std::memcmp(fast, plain, sizeof(int32_t) * n * n))
        << "n " << n << ", qp " << qp << ", trial " << trial;
  }
}

// n x n blocks (n = 4, 8) around their 32-bit path's bound on L = sum |level| x 2^(qp'/6)
// (inverse_residual.cpp: 29 L <= 2^24 for 4x4, 15 L + 64 <= 2^24 for 8x8): dense and sparse,
// every sign, single huge levels and INT32_MIN, from tiny blocks to twice the bound, and huge
// levels whose 32-bit magnitude sum wraps.
void check_inverse_residual_at_bound(int n, int64_t scale, int64_t offset, uint32_t seed) {
  std::mt19937 rng(seed);
  const int count = n * n;
  const int64_t bound = int64_t{1} << 24, limit = (bound - offset) / scale;
  int within = 0, beyond = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const int qp = static_cast<int>(rng() % 100), per = qp / 6;
    const int64_t target = std::max<int64_t>(
        1, static_cast<int64_t>(static_cast<double>(limit) * (rng() % 2001) / 1000.0));
    int64_t left = std::max<int64_t>(1, target >> per);
    int32_t levels[64] = {};
    const int nonzero = trial % 4 == 0 ? count : 1 + static_cast<int>(rng() % 12);
    for (int i = 0; i < nonzero && left > 0; ++i) {
      const int64_t m = i + 1 == nonzero ? left : 1 + static_cast<int64_t>(rng() % left);
      const auto v = static_cast<int32_t>(std::min<int64_t>(m, int64_t{1} << 30));
      levels[rng() % count] = rng() % 2 ? v : -v;
      left -= m;
    }
    if (trial % 997 == 5) levels[rng() % count] = std::numeric_limits<int32_t>::min();
    int64_t sum = 0;
    for (int i = 0; i < count; ++i) sum += std::abs(static_cast<int64_t>(levels[i]));
    (scale * (sum << per) + offset <= bound ? within : beyond) += 1;
    int32_t fast[64], plain[64];
    inverse_residual(n, levels, qp, fast);
    inverse_residual_reference(n, levels, qp, plain);
    ASSERT_EQ(0, std::memcmp(fast, plain, sizeof(int32_t) * count))
        << "n " << n << ", qp " << qp << ", trial " << trial;
  }
  EXPECT_GT(within, 5000) << n;
  EXPECT_GT(beyond, 5000) << n;
  // Huge levels whose magnitudes wrap a 32-bit sum to a small one (eight lanes apart, as a
  // vector adds them): the bound must still send them to the reference.
  const int32_t wrap_pairs[][2] = {
      {std::numeric_limits<int32_t>::min(), std::numeric_limits<int32_t>::min()},
      {std::numeric_limits<int32_t>::max(), -(1 << 30) - 1}};
  for (const auto& pair : wrap_pairs)
    for (int qp : {0, 37, 99}) {
      int32_t levels[64] = {};
      levels[0] = pair[0];
      levels[8] = pair[1];
      levels[count - 1] = 1;
      int32_t fast[64], plain[64];
      inverse_residual(n, levels, qp, fast);
      inverse_residual_reference(n, levels, qp, plain);
      ASSERT_EQ(0, std::memcmp(fast, plain, sizeof(int32_t) * count)) << "n " << n << ", qp " << qp;
    }
}

TEST(DecoderKernels, InverseResidual4x4And8x8EqualTheReferenceAtTheirBound) {
  check_inverse_residual_at_bound(4, 29, 0, 21);
  check_inverse_residual_at_bound(8, 15, 64, 22);
}

// 16x16 blocks with huge levels stacked in one column, so that a 32-bit sum of magnitudes per
// column (lane) wraps to a small number: the fast paths must still leave them to the reference.
TEST(DecoderKernels, InverseResidual16x16HugeLevelsTakeTheReference) {
  for (const int32_t magnitude : {1 << 29, 1 << 28, (1 << 30) + 12345}) {
    for (const int rows_used : {8, 16}) {
      for (const int qp : {0, 3, 40}) {
        int32_t levels[256] = {};
        for (int l = 0; l < rows_used; ++l) levels[16 * l + 3] = l % 3 ? magnitude : -magnitude;
        int32_t fast[256], plain[256];
        inverse_residual(16, levels, qp, fast);
        inverse_residual_reference(16, levels, qp, plain);
        ASSERT_EQ(0, std::memcmp(fast, plain, sizeof fast))
            << "magnitude " << magnitude << ", rows " << rows_used << ", qp " << qp;
      }
    }
  }
}

TEST(DecoderKernels, PredictMotionBlockEqualsTheReference) {
  std::mt19937 rng(14);
  const int sizes[][2] = {{16, 16}, {16, 8}, {8, 16}, {8, 8}, {6, 16},
                          {16, 2},  {6, 2},  {4, 4},  {1, 1}, {5, 3}};
  for (const int bit_depth : {8, 16}) {
    const SamplePlane ref = random_plane(48, 48, (1 << bit_depth) - 1, rng);
    for (const auto& size : sizes)
      for (int trial = 0; trial < 60; ++trial) {
        // Inside the picture, and across every edge (positions and vectors up to a block out).
        const int x0 = static_cast<int>(rng() % 48) - 8, y0 = static_cast<int>(rng() % 48) - 8;
        const int mv_x = static_cast<int>(rng() % 161) - 80,
                  mv_y = static_cast<int>(rng() % 161) - 80;
        for (const bool quarter_pel : {true, false}) {
          int32_t fast[256], plain[256];
          predict_motion_block(ref, x0, y0, size[0], size[1], mv_x, mv_y, quarter_pel, bit_depth,
                               fast);
          predict_motion_block_reference(ref, x0, y0, size[0], size[1], mv_x, mv_y, quarter_pel,
                                         bit_depth, plain);
          ASSERT_EQ(0, std::memcmp(fast, plain, sizeof(int32_t) * size[0] * size[1]))
              << size[0] << "x" << size[1] << " at (" << x0 << ", " << y0 << "), mv (" << mv_x
              << ", " << mv_y << "), " << bit_depth << " bits";
        }
      }
  }
}

TEST(DecoderKernels, StoreReconstructionEqualsTheReference) {
  std::mt19937 rng(15);
  std::uniform_int_distribution<int32_t> any(INT32_MIN, INT32_MAX), near(-70000, 140000);
  for (int trial = 0; trial < 600; ++trial) {
    const int n = 4 << (trial % 3);
    const int max_value = trial % 2 ? 65535 : 255;
    int32_t pred[16 * 20], residual[256];
    // Realistic sums around the range, and extremes whose 32-bit sums overflow.
    for (int32_t& v : pred) v = trial % 5 == 0 ? any(rng) : near(rng);
    for (int32_t& v : residual) v = trial % 5 == 0 ? any(rng) : near(rng) / 2;
    for (const bool with_residual : {true, false}) {
      uint16_t fast[20 * 20] = {}, plain[20 * 20] = {};
      store_reconstruction(n, pred, 20, with_residual ? residual : nullptr, max_value, fast + 21,
                           20);
      store_reconstruction_reference(n, pred, 20, with_residual ? residual : nullptr, max_value,
                                     plain + 21, 20);
      ASSERT_EQ(0, std::memcmp(fast, plain, sizeof fast)) << "n " << n << ", trial " << trial;
    }
  }
}

// Smooth planes with steps at the block edges (what the filter acts on), noise, and every
// strength, threshold and bit depth.
TEST(DecoderKernels, DeblockPlaneEqualsTheReference) {
  std::mt19937 rng(16);
  for (int trial = 0; trial < 60; ++trial) {
    const int width = 8 * (1 + static_cast<int>(rng() % 6)),
              height = 8 * (1 + static_cast<int>(rng() % 6));
    const int bit_depth = trial % 3 == 0 ? 8 : 16, max_value = (1 << bit_depth) - 1;
    SamplePlane plane;
    plane.width = width;
    plane.height = height;
    plane.samples.resize(static_cast<size_t>(width) * height);
    std::uniform_int_distribution<int> noise(-(1 << (bit_depth - 6)), 1 << (bit_depth - 6));
    const int step = static_cast<int>(rng() % (max_value / 8 + 1));
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const int ramp = (x * 37 + y * 23) * max_value / (width * 37 + height * 23);
        const int blocky = ((x / 8 + y / 8) % 2) * step + (trial % 4 == 3 ? noise(rng) * 64 : 0);
        plane.at(x, y) =
            static_cast<uint16_t>(std::clamp(ramp + blocky + noise(rng), 0, max_value));
      }
    if (trial % 10 == 9)  // extremes
      for (uint16_t& v : plane.samples) v = static_cast<uint16_t>(rng() % 2 ? max_value : 0);
    DeblockingStrengths strengths;
    strengths.reset(width / 4, height / 4);
    for (uint8_t& v : strengths.vertical) v = static_cast<uint8_t>(rng() % 3);
    for (uint8_t& v : strengths.horizontal) v = static_cast<uint8_t>(rng() % 3);
    DeblockingParams params;
    params.beta = 1 + static_cast<int>(rng() % 255);
    params.tc = 1 + static_cast<int>(rng() % 255);
    const int qp = static_cast<int>(rng() % 100);
    SamplePlane fast = plane, plain = plane;
    deblock_plane(fast, strengths, qp, bit_depth, params);
    deblock_plane_reference(plain, strengths, qp, bit_depth, params);
    ASSERT_EQ(fast.samples, plain.samples) << "trial " << trial << ", qp " << qp;
  }
}

TEST(DecoderKernels, UpsampleHalfPlaneEqualsTheReference) {
  std::mt19937 rng(11);
  // Even and odd sizes, a plane narrower than one vector, and every bit depth's clamp.
  const int sizes[][2] = {{320, 320}, {33, 17}, {7, 5}, {64, 1}, {1, 9}, {250, 62}};
  for (const auto& size : sizes)
    for (const int bit_depth : {8, 12, 16}) {
      const int width = size[0], height = size[1];
      const SamplePlane half = random_plane(padded(half_size(width)), padded(half_size(height)),
                                            (1 << bit_depth) - 1, rng);
      const SamplePlane fast = upsample_half_plane(half, width, height, bit_depth);
      const SamplePlane plain = upsample_half_plane_reference(half, width, height, bit_depth);
      ASSERT_EQ(fast.width, plain.width);
      ASSERT_EQ(fast.height, plain.height);
      ASSERT_EQ(fast.samples, plain.samples) << width << "x" << height << ", " << bit_depth;
    }
}

TEST(DecoderKernels, DequantizeGeometryEqualsTheReference) {
  std::mt19937 rng(12);
  for (const bool texture : {false, true})
    for (const int size : {320, 37, 5}) {
      SequenceInfo info;
      info.width = info.height = size;
      info.bit_depth = 16;
      info.has_texture = texture;
      info.box_min_mm = cv::Vec3d(-66.8115, -112.3237, 613.4776);
      info.box_max_mm = cv::Vec3d(74.5544, 88.4242, 712.1782);
      info.domain_mask = cv::Mat(size, size, CV_8U, cv::Scalar(255));
      std::vector<SamplePlane> planes;
      for (int a = 0; a < (texture ? 4 : 3); ++a)
        planes.push_back(random_plane(padded(size), padded(size), a < 3 ? 65535 : 255, rng));
      const GeometryImage fast = dequantize_geometry(planes, info, 3);
      const GeometryImage plain = dequantize_geometry_reference(planes, info, 3);
      ASSERT_EQ(fast.xyz_mm.size(), plain.xyz_mm.size());
      EXPECT_EQ(0, std::memcmp(fast.xyz_mm.data, plain.xyz_mm.data,
                               plain.xyz_mm.total() * plain.xyz_mm.elemSize()))
          << size;
      ASSERT_EQ(fast.texture.empty(), !texture);
      if (texture) {
        EXPECT_EQ(0, std::memcmp(fast.texture.data, plain.texture.data,
                                 plain.texture.total() * plain.texture.elemSize()));
      }
      EXPECT_EQ(fast.index, 3);
      EXPECT_EQ(fast.timestamp, plain.timestamp);
    }
}

}  // namespace
}  // namespace gvkit::codec
