// Intra predictors: the block-at-a-time versions equal the per-sample reference on random
// neighbours for every size and mode, and the geometry modes predict tilted planes exactly.
#include <random>

#include <gtest/gtest.h>

#include "gvkit/codec/intra_prediction.hpp"

namespace gvkit::codec {
namespace {

IntraNeighbors random_neighbors(std::mt19937& rng, int max_value) {
  std::uniform_int_distribution<int> u(0, max_value);
  IntraNeighbors nb;
  nb.corner = u(rng);
  for (int& v : nb.top) v = u(rng);
  for (int& v : nb.left) v = u(rng);
  return nb;
}

TEST(IntraPrediction, OptimisedEqualsReferenceOnRandomNeighbours) {
  std::mt19937 rng(3);
  const struct {
    int n, modes;
  } sizes[] = {{4, kIntra4x4ModeCount}, {8, kIntra8x8ModeCount}, {16, kIntra16x16ModeCount}};
  for (int bit_depth : {8, 12, 16}) {
    const int max_value = (1 << bit_depth) - 1;
    for (int trial = 0; trial < 200; ++trial) {
      const IntraNeighbors nb = random_neighbors(rng, max_value);
      for (const auto& s : sizes)
        for (int mode = 0; mode < s.modes; ++mode) {
          int32_t fast[256], ref[256];
          predict_intra(s.n, mode, nb, max_value, fast);
          predict_intra_reference(s.n, mode, nb, max_value, ref);
          for (int i = 0; i < s.n * s.n; ++i)
            ASSERT_EQ(fast[i], ref[i]) << "n " << s.n << " mode " << mode << " sample " << i;
        }
      int32_t all[kIntra4x4ModeCount][16];
      predict_intra4x4_modes(nb, max_value, kIntra4x4ModeCount, all);
      for (int mode = 0; mode < kIntra4x4ModeCount; ++mode) {
        int32_t ref[16];
        predict_intra_reference(4, mode, nb, max_value, ref);
        for (int i = 0; i < 16; ++i) ASSERT_EQ(all[mode][i], ref[i]) << "all modes, mode " << mode;
      }
    }
  }
}

// Neighbours of the 4x4 block at the origin of the plane a + b x + c y.
IntraNeighbors plane_neighbors(int a, int b, int c) {
  IntraNeighbors nb;
  nb.corner = a - b - c;
  for (int x = 0; x < 8; ++x) nb.top[x] = a + b * x - c;
  for (int y = 0; y < 4; ++y) nb.left[y] = a - b + c * y;
  return nb;
}

TEST(IntraPrediction, GeometryModesPredictTiltedPlanesExactly) {
  const int max_value = 65535;
  for (int b : {-300, -7, 0, 3, 41, 1000})
    for (int c : {-999, -2, 0, 5, 77}) {
      const int a = 30000;
      const IntraNeighbors nb = plane_neighbors(a, b, c);
      for (int mode = kIntraGeoPlane; mode <= kIntraGeoMeanPlane; ++mode) {
        int32_t pred[16], ref[16];
        predict_intra(4, mode, nb, max_value, pred);
        predict_intra_reference(4, mode, nb, max_value, ref);
        for (int y = 0; y < 4; ++y)
          for (int x = 0; x < 4; ++x) {
            ASSERT_EQ(pred[y * 4 + x], a + b * x + c * y)
                << "mode " << mode << " b " << b << " c " << c << " at " << x << "," << y;
            ASSERT_EQ(ref[y * 4 + x], a + b * x + c * y);
          }
      }
    }
}

TEST(IntraPrediction, SeedsPrintedModeOneWouldMissThePlaneByTwoC) {
  // The seed's printed mode 1, P(x,y-1) + [N(x-1,y-1) - N(x-1,y)], steps by -c per row: its first
  // row is off by 2c. Our kIntraGeoPlane (the gradient-continuation intent) is exact.
  const int a = 1000, b = 3, c = 5;
  const IntraNeighbors nb = plane_neighbors(a, b, c);
  const int printed_row0 = nb.top[0] + (nb.corner - nb.left[0]);
  EXPECT_EQ(printed_row0 - a, -2 * c);
  int32_t pred[16];
  predict_intra(4, kIntraGeoPlane, nb, 65535, pred);
  EXPECT_EQ(pred[0], a);
}

TEST(IntraPrediction, NeighboursSubstituteMissingSides) {
  std::vector<uint16_t> plane(32 * 32);
  for (int i = 0; i < 32 * 32; ++i) plane[i] = static_cast<uint16_t>(i);
  const IntraNeighbors none = make_neighbors(plane.data(), 32, 0, 0, 4, false, false, false, 16);
  EXPECT_EQ(none.corner, 32768);
  EXPECT_EQ(none.top[7], 32768);
  const IntraNeighbors top_only = make_neighbors(plane.data(), 32, 4, 4, 4, true, false, false, 16);
  EXPECT_EQ(top_only.top[0], 3 * 32 + 4);
  EXPECT_EQ(top_only.top[5], top_only.top[3]);  // no top-right: repeat
  EXPECT_EQ(top_only.left[2], top_only.top[0]);
  const IntraNeighbors all = make_neighbors(plane.data(), 32, 4, 4, 4, true, true, true, 16);
  EXPECT_EQ(all.corner, 3 * 32 + 3);
  EXPECT_EQ(all.top[5], 3 * 32 + 9);
  EXPECT_EQ(all.left[3], 7 * 32 + 3);
}

}  // namespace
}  // namespace gvkit::codec
