// The encoder's optimised kernels return exactly what their plain reference versions return: SAD
// and SATD (SSE2, and AVX2 where the processor has it), table-driven quantization and its
// numerators, quarter-sample prediction from precomputed half-sample planes (inside the margin
// and beyond it, at every phase, at 8 and 16 bits), and a geometry image's quantization into
// coded planes.
#include <random>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <vector>

#include "gvkit/codec/block_distortion.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/motion_compensation.hpp"
#include "gvkit/codec/transform.hpp"

#include "codec/random_sample_plane.hpp"

namespace gvkit::codec {
namespace {

using testing::random_plane;

TEST(EncoderKernels, SadAndSatdEqualTheReference) {
  std::mt19937 rng(7);
  const SamplePlane a = random_plane(40, 40, 65535, rng), b = random_plane(40, 40, 65535, rng);
  for (int trial = 0; trial < 200; ++trial) {
    const int ax = rng() % 24, ay = rng() % 24, bx = rng() % 24, by = rng() % 24;
    const uint16_t* pa = &a.samples[ay * 40 + ax];
    const uint16_t* pb = &b.samples[by * 40 + bx];
    ASSERT_EQ(sad16x16(pa, 40, pb, 40), sad16x16_reference(pa, 40, pb, 40));
    // Predictions as the encoder makes them: in range, or (temporal difference) beyond it.
    int32_t pred[256];
    std::uniform_int_distribution<int> u(trial % 2 ? -32768 : 0, trial % 2 ? 98303 : 65535);
    for (int32_t& v : pred) v = trial % 5 == 0 ? (trial % 10 ? 98303 : -32768) : u(rng);
    for (int n : {4, 8, 16}) {
      ASSERT_EQ(satd_block(n, pa, 40, pred), satd_block_reference(n, pa, 40, pred)) << n;
      ASSERT_EQ(sad_block(n, pa, 40, pred), sad_block_reference(n, pa, 40, pred)) << n;
    }
    // Many 4x4 predictions against one source block at once.
    int32_t preds[16][16];
    for (int m = 0; m < 16; ++m)
      for (int i = 0; i < 16; ++i) preds[m][i] = pred[(m * 16 + i * 7) % 256];
    for (bool sad : {false, true}) {
      int64_t out[16];
      const int count = trial % 2 ? 13 : 16;  // an odd count too (the paired AVX2 path's tail)
      distortions4x4(sad, pa, 40, preds, count, out);
      for (int m = 0; m < count; ++m)
        ASSERT_EQ(out[m], sad ? sad_block_reference(4, pa, 40, preds[m])
                              : satd_block_reference(4, pa, 40, preds[m]));
      // The source less a shared term t, against the predictions without it: the same figures
      // as the source against the predictions plus t (and as the plain loops).
      int32_t term[16], source[16], shifted[16][16];
      std::uniform_int_distribution<int> t(-65535, 65535);
      for (int i = 0; i < 16; ++i) {
        term[i] = trial % 3 == 0 ? 0 : t(rng);
        source[i] = static_cast<int32_t>(pa[(i / 4) * 40 + i % 4]) - term[i];
      }
      for (int m = 0; m < count; ++m)
        for (int i = 0; i < 16; ++i) shifted[m][i] = preds[m][i] + term[i];
      int64_t with_term[16], of[16], of_reference[16];
      distortions4x4(sad, pa, 40, shifted, count, with_term);
      distortions4x4_of(sad, source, preds, count, of);
      distortions4x4_of_reference(sad, source, preds, count, of_reference);
      for (int m = 0; m < count; ++m) {
        ASSERT_EQ(of[m], with_term[m]);
        ASSERT_EQ(of[m], of_reference[m]);
      }
    }
  }
  // All-max against all-zero: the largest SAD.
  const SamplePlane hi = random_plane(16, 16, 0, rng);
  SamplePlane full = hi;
  for (uint16_t& v : full.samples) v = 65535;
  EXPECT_EQ(sad16x16(full.samples.data(), 16, hi.samples.data(), 16), 256 * 65535);
}

TEST(EncoderKernels, QuantizationEqualsTheReference) {
  std::mt19937 rng(11);
  for (int qp = 0; qp <= 99; ++qp)
    for (int n : {4, 8}) {
      int32_t coeffs[64], fast[64], ref[64];
      std::uniform_int_distribution<int> u(-(1 << 22), 1 << 22);
      for (int32_t& c : coeffs) c = u(rng);
      quantize(n, coeffs, qp, fast);
      quantize_reference(n, coeffs, qp, ref);
      for (int i = 0; i < n * n; ++i) ASSERT_EQ(fast[i], ref[i]) << "qp " << qp << " n " << n;
      int64_t dq_fast[64], dq_ref[64];
      dequantize(n, fast, qp, dq_fast);
      dequantize_reference(n, fast, qp, dq_ref);
      for (int i = 0; i < n * n; ++i) ASSERT_EQ(dq_fast[i], dq_ref[i]) << "qp " << qp;
    }
}

// The numerators of quantization: |value| x factor in 64 bits, for every count (the vector part
// and the tail), the extreme values (INT32_MIN, INT32_MAX) and factors up to 2^31 - 1.
TEST(EncoderKernels, AbsoluteProductsEqualThePlainProducts) {
  std::mt19937 rng(12);
  const int32_t extremes[] = {std::numeric_limits<int32_t>::min(),
                              std::numeric_limits<int32_t>::max(), 0, 1, -1};
  for (int trial = 0; trial < 3000; ++trial) {
    const int count = trial % 70;
    std::vector<int32_t> values(count), factors(count);
    for (int k = 0; k < count; ++k) {
      values[k] = rng() % 8 == 0 ? extremes[rng() % 5] : static_cast<int32_t>(rng());
      factors[k] = static_cast<int32_t>(rng() % (trial % 3 == 0 ? 0x80000000u : 20973u));
    }
    const int32_t one = factors.empty() ? 7 : factors[0];
    std::vector<int64_t> by_position(count), by_one(count);
    absolute_products(values.data(), factors.data(), count, by_position.data());
    absolute_products(values.data(), one, count, by_one.data());
    for (int k = 0; k < count; ++k) {
      const int64_t magnitude = std::llabs(int64_t{values[k]});
      ASSERT_EQ(by_position[k], magnitude * factors[k]) << trial << " " << k;
      ASSERT_EQ(by_one[k], magnitude * one) << trial << " " << k;
    }
  }
}

TEST(EncoderKernels, InterpolatedReferenceEqualsTheSampleBySamplePrediction) {
  std::mt19937 rng(5);
  for (int bit_depth : {8, 16}) {
    const SamplePlane ref = random_plane(48, 32, (1 << bit_depth) - 1, rng);
    const InterpolatedReference interp(ref, bit_depth, 6);
    for (int trial = 0; trial < 400; ++trial) {
      const int w = trial % 3 == 0 ? 4 : 16, h = w;
      const int x0 = w * static_cast<int>(rng() % (48 / w)),
                y0 = h * static_cast<int>(rng() % (32 / h));
      // Vectors reaching inside the margin and (every fourth) far beyond it.
      const int reach = trial % 4 == 0 ? 120 : 36;
      const int mv_x = static_cast<int>(rng() % (2 * reach + 1)) - reach;
      const int mv_y = static_cast<int>(rng() % (2 * reach + 1)) - reach;
      const bool quarter_pel = trial % 7 != 0;
      int32_t fast[256], slow[256];
      interp.predict(x0, y0, w, h, mv_x, mv_y, quarter_pel, fast);
      predict_motion_block_reference(ref, x0, y0, w, h, mv_x, mv_y, quarter_pel, bit_depth, slow);
      for (int i = 0; i < w * h; ++i)
        ASSERT_EQ(fast[i], slow[i]) << "block (" << x0 << ", " << y0 << ") vector (" << mv_x << ", "
                                    << mv_y << ") sample " << i;
      EXPECT_EQ(interp.sample(x0 + 3, y0 + 2, mv_x, mv_y, quarter_pel),
                motion_sample(ref, x0 + 3, y0 + 2, mv_x, mv_y, quarter_pel, bit_depth));
    }
    // The whole-sample block inside the margin is the edge-extended plane.
    const uint16_t* block = interp.whole_block(-6, -6, 16, 16);
    ASSERT_NE(block, nullptr);
    EXPECT_EQ(block[0], ref.at(0, 0));
    EXPECT_EQ(block[15 * interp.stride() + 15], ref.at(9, 9));
    EXPECT_EQ(interp.whole_block(-7, 0, 16, 16), nullptr);
    EXPECT_EQ(interp.whole_block(48 + 6 - 16, 32 + 6 - 16, 16, 16) != nullptr, true);
    EXPECT_EQ(interp.whole_block(48 + 6 - 15, 0, 16, 16), nullptr);
  }
}

// The sub-sample search's cost straight from the stored half-sample rows: at every phase, where
// quarter_block_rows finds the block within the margin, the rows' (averaged) samples are
// predict()'s and satd_block_of_average is satd_block of that prediction (and its plain
// version's), for 8x8 and 16x16 blocks at 8 and 16 bits with sources at the range's ends; beyond
// the margin it declines.
TEST(EncoderKernels, SubsampleSatdFromStoredRowsEqualsThatOfThePrediction) {
  std::mt19937 rng(9);
  int inside = 0, outside = 0, averaged = 0;
  for (int bit_depth : {8, 16}) {
    const int top = (1 << bit_depth) - 1;
    const SamplePlane ref = random_plane(48, 48, top, rng);
    const SamplePlane src = random_plane(48, 48, top, rng);
    const InterpolatedReference interp(ref, bit_depth, 6);
    for (int trial = 0; trial < 400; ++trial) {
      const int n = trial % 3 == 1 ? 8 : 16;
      const int x0 = n * static_cast<int>(rng() % (48 / n)),
                y0 = n * static_cast<int>(rng() % (48 / n));
      const int reach = trial % 4 == 0 ? 120 : 28;
      const int mv_x = static_cast<int>(rng() % (2 * reach + 1)) - reach;
      const int mv_y = static_cast<int>(rng() % (2 * reach + 1)) - reach;
      const uint16_t *first = nullptr, *second = nullptr;
      if (!interp.quarter_block_rows(x0, y0, n, n, mv_x, mv_y, &first, &second)) {
        ++outside;
        continue;
      }
      ++inside;
      averaged += second != nullptr;
      int32_t pred[256];
      interp.predict(x0, y0, n, n, mv_x, mv_y, true, pred);
      for (int i = 0; i < n * n; ++i) {
        const ptrdiff_t at = (i / n) * interp.stride() + i % n;
        ASSERT_EQ(second ? (first[at] + second[at] + 1) >> 1 : first[at], pred[i])
            << "vector (" << mv_x << ", " << mv_y << ") sample " << i;
      }
      // Sources at the range's ends (every third trial) and random.
      std::vector<uint16_t> extreme(256, trial % 2 ? top : 0);
      const uint16_t* s = trial % 3 == 0 ? extreme.data() : &src.samples[y0 * 48 + x0];
      const ptrdiff_t s_stride = trial % 3 == 0 ? 16 : 48;
      const int64_t expected = satd_block(n, s, s_stride, pred);
      ASSERT_EQ(satd_block_of_average(n, s, s_stride, first, second, interp.stride()), expected)
          << n;
      ASSERT_EQ(satd_block_of_average_reference(n, s, s_stride, first, second, interp.stride()),
                expected);
    }
  }
  EXPECT_GT(inside, 300);
  EXPECT_GT(averaged, 100);
  EXPECT_GT(outside, 50);
}

// Positions inside and outside the box, halves, non-finite values and texture values beyond
// [0, 1], at sizes that are not multiples of 4 or 16, with and without a texture, at 16 and 10
// bits: the same samples as the plain version.
TEST(EncoderKernels, QuantizeGeometryEqualsTheReference) {
  std::mt19937 rng(11);
  const float nan = std::numeric_limits<float>::quiet_NaN(),
              inf = std::numeric_limits<float>::infinity();
  for (const cv::Size size : {cv::Size(37, 29), cv::Size(64, 48), cv::Size(101, 7)})
    for (const bool texture : {false, true})
      for (const int bit_depth : {16, 10}) {
        SequenceInfo info;
        info.width = size.width;
        info.height = size.height;
        info.bit_depth = bit_depth;
        info.has_texture = texture;
        // A step of 2^-6 mm, so that positions halfway between two samples are exact in float.
        const double extent = ((1 << bit_depth) - 1) / 64.0;
        info.box_min_mm = cv::Vec3d(-8, -8, 600);
        info.box_max_mm = info.box_min_mm + cv::Vec3d(extent, extent, extent);
        GeometryImage image;
        image.xyz_mm = cv::Mat(size, CV_32FC3);
        image.domain_mask = cv::Mat(size, CV_8U, cv::Scalar(0));
        if (texture) image.texture = cv::Mat(size, CV_32F);
        std::uniform_real_distribution<float> u(-0.1f, 1.1f), t(-0.2f, 1.2f);
        const double step = info.step_mm();
        for (int y = 0; y < size.height; ++y)
          for (int x = 0; x < size.width; ++x) {
            cv::Vec3f& p = image.xyz_mm.at<cv::Vec3f>(y, x);
            for (int a = 0; a < 3; ++a) {
              const double lo = info.box_min_mm[a], hi = info.box_max_mm[a];
              switch (rng() % 8) {
                case 0:  // exactly halfway between two samples, inside the box or below it
                  p[a] =
                      static_cast<float>(lo + (static_cast<int>(rng() % 1000) - 20 + 0.5) * step);
                  break;
                case 1:
                  p[a] = rng() % 2 ? nan : (rng() % 2 ? inf : -inf);
                  break;
                case 2:
                  p[a] = static_cast<float>(rng() % 2 ? 1e30 : -1e30);
                  break;
                default:
                  p[a] = static_cast<float>(lo + u(rng) * (hi - lo));
              }
            }
            if (texture) image.texture.at<float>(y, x) = rng() % 16 ? t(rng) : nan;
            image.domain_mask.at<uint8_t>(y, x) = rng() % 5 ? 255 : 0;
          }
        info.domain_mask = image.domain_mask;
        const std::vector<SamplePlane> fast = quantize_geometry(image, info);
        const std::vector<SamplePlane> plain = quantize_geometry_reference(image, info);
        ASSERT_EQ(fast.size(), plain.size());
        for (size_t i = 0; i < fast.size(); ++i) {
          EXPECT_EQ(fast[i].width, plain[i].width);
          EXPECT_EQ(fast[i].height, plain[i].height);
          EXPECT_TRUE(fast[i].samples == plain[i].samples)
              << size << " plane " << i << " bit depth " << bit_depth;
        }
      }
}

}  // namespace
}  // namespace gvkit::codec
