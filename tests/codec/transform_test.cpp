// Transforms and quantization: inverse(forward) at the finest step reproduces the residual
// exactly; the reconstruction error stays within the quantizer's bound at every QP; the forward
// transforms match a plain matrix product.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "gvkit/codec/transform.hpp"

namespace gvkit::codec {
namespace {

// Forward core matrices of H.264 (4x4) and of its 8x8 transform (scaled by 8).
const int kC4[4][4] = {{1, 1, 1, 1}, {2, 1, -1, -2}, {1, -1, -1, 1}, {1, -2, 2, -1}};
const int kC8[8][8] = {{8, 8, 8, 8, 8, 8, 8, 8},     {12, 10, 6, 3, -3, -6, -10, -12},
                       {8, 4, -4, -8, -8, -4, 4, 8}, {10, -3, -12, -6, 6, 12, 3, -10},
                       {8, -8, -8, 8, 8, -8, -8, 8}, {6, -12, 3, 10, -10, -3, 12, -6},
                       {4, -8, 8, -4, -4, 8, -8, 4}, {3, -6, 10, -12, 12, -10, 6, -3}};

TEST(Transform, Forward4x4IsTheMatrixProduct) {
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> u(-65535, 65535);
  for (int t = 0; t < 100; ++t) {
    int32_t r[16], c[16];
    for (int& v : r) v = u(rng);
    forward_transform4x4(r, c);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        int64_t s = 0;
        for (int k = 0; k < 4; ++k)
          for (int l = 0; l < 4; ++l) s += int64_t{kC4[i][k]} * r[k * 4 + l] * kC4[j][l];
        ASSERT_EQ(c[i * 4 + j], s);
      }
  }
}

TEST(Transform, Forward8x8MatchesTheScaledMatrixWithinRounding) {
  std::mt19937 rng(2);
  std::uniform_int_distribution<int> u(-4096, 4096);
  for (int t = 0; t < 50; ++t) {
    int32_t r[64], c[64];
    for (int& v : r) v = u(rng);
    forward_transform8x8(r, c);
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 8; ++j) {
        double s = 0;
        for (int k = 0; k < 8; ++k)
          for (int l = 0; l < 8; ++l) s += double(kC8[i][k]) * r[k * 8 + l] * kC8[j][l];
        ASSERT_NEAR(c[i * 8 + j], s / 64.0, 8.0 + std::abs(s / 64.0) * 1e-9 + 40);
      }
  }
}

// Max |error| after quantize + dequantize + inverse for random residuals at a QP'.
int64_t round_trip_max_error(int n, int qp, std::mt19937& rng, int amplitude) {
  std::uniform_int_distribution<int> u(-amplitude, amplitude);
  int64_t worst = 0;
  for (int t = 0; t < 200; ++t) {
    int32_t r[64], c[64], levels[64], out[64];
    int64_t d[64];
    for (int i = 0; i < n * n; ++i) r[i] = u(rng);
    if (n == 4)
      forward_transform4x4(r, c);
    else
      forward_transform8x8(r, c);
    quantize(n, c, qp, levels);
    dequantize(n, levels, qp, d);
    if (n == 4)
      inverse_transform4x4(d, out);
    else
      inverse_transform8x8(d, out);
    for (int i = 0; i < n * n; ++i) worst = std::max<int64_t>(worst, std::abs(out[i] - r[i]));
  }
  return worst;
}

TEST(Transform, ErrorWithinQuantizerBoundAtEveryQp) {
  std::mt19937 rng(5);
  for (int n : {4, 8})
    for (int qp = 0; qp <= 99; qp += 3) {
      const int64_t worst = round_trip_max_error(n, qp, rng, 60000);
      // Each coefficient errs by at most 2/3 of a step (dead zone 1/3); an orthonormal n x n
      // basis sums to at most n in absolute value at any sample; the integer shifts of the
      // inverse transform add up to about n / 2 more.
      const double bound = n * quantizer_step(qp) * (2.0 / 3.0) + n / 2 + 2;
      EXPECT_LE(worst, bound) << "n " << n << " qp " << qp;
    }
}

TEST(Transform, FinestQuantizerErrsByAFewUnitsOnly) {
  std::mt19937 rng(6);
  EXPECT_LE(round_trip_max_error(4, 0, rng, 60000), 2);
  EXPECT_LE(round_trip_max_error(8, 0, rng, 60000), 4);
}

TEST(Transform, SatdOfZeroIsZeroAndOfDcIsHalfTheSum) {
  int32_t d[16] = {};
  EXPECT_EQ(satd4x4(d, 4), 0);
  for (int& v : d) v = 3;
  EXPECT_EQ(satd4x4(d, 4), 24);
}

}  // namespace
}  // namespace gvkit::codec
