// Motion search of a macroblock: on a smooth surface shifted by a known vector, both the full and
// the diamond integer search find the whole-sample part, the sub-sample refinement the quarter
// samples, and the diamond search stays within the search range.
#include <cmath>

#include <gtest/gtest.h>

#include "gvkit/codec/motion_search.hpp"

namespace gvkit::codec {
namespace {

// A smooth 16-bit surface sampled at (x + dx, y + dy).
SamplePlane smooth_plane(int size, double dx, double dy) {
  SamplePlane p;
  p.width = p.height = size;
  p.samples.resize(static_cast<size_t>(size) * size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double u = x + dx, v = y + dy;
      p.at(x, y) = static_cast<uint16_t>(
          std::lround(30000 + 9000 * std::sin(u * 0.21) * std::cos(v * 0.17) + 40 * u - 25 * v));
    }
  return p;
}

TEST(MotionSearch, FindsAKnownShiftWithBothPatterns) {
  const SamplePlane ref = smooth_plane(64, 0, 0);
  // The frame is the reference moved by (-3, +2) samples: its block at (x0, y0) is the
  // reference's at (x0 + 3, y0 - 2).
  const SamplePlane cur = smooth_plane(64, 3, -2);
  const InterpolatedReference interp(ref, 16, 8);
  for (MotionSearchPattern pattern : {MotionSearchPattern::kFull, MotionSearchPattern::kDiamond}) {
    MotionSearchParams params;
    params.pattern = pattern;
    params.range = 4;
    params.lambda = 4;
    const MotionSearchResult whole = search_motion_16x16(cur, interp, 16, 16, 0, 0, params);
    EXPECT_EQ(whole.mv_x, 3);
    EXPECT_EQ(whole.mv_y, -2);
    params.subpel = 4;
    const MotionSearchResult quarter = search_motion_16x16(cur, interp, 16, 32, 0, 0, params);
    EXPECT_EQ(quarter.whole_mv_x, 12);
    EXPECT_EQ(quarter.whole_mv_y, -8);
    EXPECT_EQ(quarter.mv_x, 12);
    EXPECT_EQ(quarter.mv_y, -8);
  }
}

TEST(MotionSearch, RefinesAQuarterSampleShiftAndKeepsToTheRange) {
  const SamplePlane ref = smooth_plane(64, 0, 0);
  const SamplePlane cur = smooth_plane(64, 1.25, 0.5);
  const InterpolatedReference interp(ref, 16, 8);
  MotionSearchParams params;
  params.pattern = MotionSearchPattern::kDiamond;
  params.subpel = 4;
  params.lambda = 1;
  const MotionSearchResult r = search_motion_16x16(cur, interp, 16, 16, 0, 0, params);
  EXPECT_EQ(r.mv_x, 5);  // 1.25 samples
  EXPECT_EQ(r.mv_y, 2);  // 0.5 samples
  // A shift beyond the range: the integer vector stops at the range.
  const SamplePlane far = smooth_plane(64, 9, 0);
  params.subpel = 0;
  params.range = 2;
  const MotionSearchResult f = search_motion_16x16(far, interp, 16, 16, 0, 0, params);
  EXPECT_LE(std::abs(f.mv_x), 2);
  EXPECT_LE(std::abs(f.mv_y), 2);
}

}  // namespace
}  // namespace gvkit::codec
