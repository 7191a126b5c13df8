// Every pattern family: generate -> "camera" (the projector image seen 1:1, with offset and
// contrast) -> decode; the decoded projector column must match the true column.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/core.hpp>

#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/phase_shift.hpp"

namespace gvkit::capture {
namespace {

constexpr int kWidth = 912, kRows = 6;

// Camera images: intensity = 0.1 + contrast * pattern (+ noise), stored at the given depth.
FringeSet capture_patterns(const PatternSet& set, int depth, double noise_sigma, uint64_t seed,
                           double contrast = 0.75, int rows = kRows) {
  FringeSet f;
  cv::RNG rng(seed);
  const double max = depth == CV_16U ? 65535.0 : 255.0;
  for (const cv::Mat& p : set.generate({kWidth, rows})) {
    cv::Mat v = 0.1 + contrast * p;
    if (noise_sigma > 0) {
      cv::Mat n(v.size(), CV_32F);
      rng.fill(n, cv::RNG::NORMAL, 0, noise_sigma);
      v += n;
    }
    cv::Mat image;
    v.convertTo(image, depth, max);
    f.images.push_back(image);
  }
  return f;
}

struct ColumnError {
  double rms = 0, max = 0;
  double valid_share = 0;
  double period_error_share = 0;  // of the valid pixels: off by half a period or more
};

// Error of the decoded column against the true one; for relative (spatially unwrapped) maps the
// offset of each region, a whole number of periods, is removed first.
ColumnError column_error(const PhaseMap& map) {
  const cv::Mat u = projector_column(map);
  double offset = 0;
  if (!map.absolute) {
    const float u0 = u.at<float>(u.rows / 2, kWidth / 2);
    offset = u0 - kWidth / 2;
    const double periods = offset / map.pitch_px;
    EXPECT_NEAR(periods, std::round(periods), 0.01) << "region offset is not whole periods";
  }
  ColumnError e;
  int n = 0, valid = 0, off = 0;
  for (int y = 0; y < u.rows; ++y)
    for (int x = 0; x < kWidth; ++x) {
      if (!map.valid.at<uint8_t>(y, x)) continue;
      ++valid;
      const double d = u.at<float>(y, x) - offset - x;
      e.rms += d * d;
      e.max = std::max(e.max, std::abs(d));
      off += std::abs(d) >= 0.5 * map.pitch_px;
      ++n;
    }
  e.rms = n ? std::sqrt(e.rms / n) : INFINITY;
  e.valid_share = static_cast<double>(valid) / (u.rows * kWidth);
  e.period_error_share = n ? static_cast<double>(off) / n : 0.0;
  return e;
}

class RoundTrip : public ::testing::TestWithParam<const char*> {};

TEST_P(RoundTrip, SixteenBitIsExact) {
  auto set = create_pattern_set(GetParam());
  ASSERT_TRUE(set) << set.status().message();
  EXPECT_EQ((*set)->name(), GetParam());
  const FringeSet f = capture_patterns(**set, CV_16U, 0, 1);
  ASSERT_EQ(static_cast<int>(f.images.size()), (*set)->image_count());
  auto map = (*set)->decode(f, kWidth);
  ASSERT_TRUE(map) << map.status().message();
  const ColumnError e = column_error(*map);
  EXPECT_GT(e.valid_share, 0.99);
  EXPECT_LT(e.rms, 0.01) << GetParam();
  EXPECT_LT(e.max, 0.05) << GetParam();
}

TEST_P(RoundTrip, EightBitWithNoiseStaysUnwrapped) {
  auto set = create_pattern_set(GetParam());
  ASSERT_TRUE(set);
  const FringeSet f = capture_patterns(**set, CV_8U, 0.01, 7);
  auto map = (*set)->decode(f, kWidth);
  ASSERT_TRUE(map) << map.status().message();
  const ColumnError e = column_error(*map);
  EXPECT_GT(e.valid_share, 0.98) << GetParam();
  // 1 % noise at 0.375 modulation: phase noise ~0.02-0.03 rad, i.e. well under a pixel; no
  // pixel may be off by a period.
  EXPECT_LT(e.rms, 0.5) << GetParam();
  EXPECT_LT(e.max, 0.25 * (*set)->pitch_px(kWidth)) << GetParam();
}

// Gray codes on a dark surface (contrast 0.1, so a bit lies 0.05 from the mean) with 1 % noise:
// now and then a bit flips, and a flipped bit moves the phase by whole periods. Such pixels are
// uncertain and take their neighbours' period order. What is left are pixels where the phase
// noise itself crosses a period edge (measured before uncertain bits were settled: 0.086 % and
// 0.039 % of the pixels a period off; after: 0.022 % and 0.009 %).
TEST(GrayCode, NoisyDarkSurfaceKeepsThePeriodOrder) {
  for (const char* name : {"gray4-psp4", "gray5-psp3"}) {
    double period_errors = 0, valid = 0;
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      auto set = create_pattern_set(name);
      ASSERT_TRUE(set);
      const FringeSet f = capture_patterns(**set, CV_16U, 0.01, seed, 0.1, 64);
      auto map = (*set)->decode(f, kWidth);
      ASSERT_TRUE(map) << map.status().message();
      const ColumnError e = column_error(*map);
      period_errors += e.period_error_share / 3;
      valid += e.valid_share / 3;
    }
    EXPECT_GT(valid, 0.99) << name;
    EXPECT_LT(period_errors, 0.0003) << name;
  }
}

INSTANTIATE_TEST_SUITE_P(Families, RoundTrip,
                         ::testing::Values("psp3-f16", "psp4-f16", "psp8-f32", "mf3-f16-f1",
                                           "mf4-f16-f1", "mf3-f64-f8-f1", "zh-f16", "gray4-psp4",
                                           "gray5-psp3"));

TEST(PatternSet, NamesAndBadNames) {
  auto skull = create_pattern_set("mf3-f16-f1");
  ASSERT_TRUE(skull);
  EXPECT_EQ((*skull)->image_count(), 6);
  EXPECT_DOUBLE_EQ((*skull)->pitch_px(1824), 114.0);  // the SLStudio skull's fine pitch
  for (const char* bad :
       {"psp2-f16", "psp3", "mf3-f16-f2", "mf3-f1-f16", "zh-f0", "gray0-psp3", "nonsense", ""}) {
    auto r = create_pattern_set(bad);
    EXPECT_FALSE(r) << bad;
    if (!r) {
      EXPECT_NE(r.status().message().find("pattern set"), std::string::npos);
    }
  }
  PatternSetOptions o;
  o.min_modulation = 2;
  EXPECT_FALSE(create_pattern_set("psp3-f16", o));
}

TEST(PatternSet, SkullConventionShiftsByMinusTwoPiKOverThree) {
  // I_k = 0.5 (1 + cos(2 pi u / p - 2 pi k / 3)) at column 0: 1, 0.25, 0.25.
  auto set = create_pattern_set("psp3-f16");
  ASSERT_TRUE(set);
  const auto images = (*set)->generate({1824, 2});
  EXPECT_NEAR(images[0].at<float>(0, 0), 1.0, 1e-6);
  EXPECT_NEAR(images[1].at<float>(0, 0), 0.25, 1e-6);
  EXPECT_NEAR(images[2].at<float>(0, 0), 0.25, 1e-6);
  // A quarter period later the phase is pi/2: image 1 peaks at u = p/3.
  EXPECT_NEAR(images[1].at<float>(0, 38), 1.0, 1e-6);
}

TEST(PhaseShiftKernel, FastMatchesReferenceOnRandomImages) {
  cv::RNG rng(3);
  for (int steps : {3, 4, 5}) {
    for (int depth : {CV_8U, CV_16U}) {
      std::vector<cv::Mat> images;
      for (int k = 0; k < steps; ++k) {
        cv::Mat im(37, 53, depth);
        rng.fill(im, cv::RNG::UNIFORM, 0, depth == CV_8U ? 256 : 65536);
        images.push_back(im);
      }
      const WrappedPhase fast = decode_phase_shift(images, 0, steps, 0.99);
      const WrappedPhase ref = decode_phase_shift_reference(images, 0, steps, 0.99);
      for (int y = 0; y < 37; ++y)
        for (int x = 0; x < 53; ++x) {
          EXPECT_NEAR(fast.modulation.at<float>(y, x), ref.modulation.at<float>(y, x), 1e-5);
          EXPECT_NEAR(fast.mean.at<float>(y, x), ref.mean.at<float>(y, x), 1e-5);
          EXPECT_EQ(fast.saturated.at<uint8_t>(y, x), ref.saturated.at<uint8_t>(y, x));
          if (ref.modulation.at<float>(y, x) > 1e-3) {
            double d = std::abs(fast.phase.at<float>(y, x) - ref.phase.at<float>(y, x));
            d = std::min(d, 2 * CV_PI - d);
            EXPECT_LT(d, 1e-4) << "steps " << steps;
          }
        }
    }
  }
}

TEST(PhaseShiftKernel, FastAtan2IsAccurate) {
  double worst = 0;
  for (int i = 0; i < 3600; ++i) {
    const double a = -CV_PI + 2 * CV_PI * i / 3600.0;
    for (double r : {1e-3, 1.0, 1e3}) {
      const float y = static_cast<float>(r * std::sin(a)), x = static_cast<float>(r * std::cos(a));
      double d = std::abs(fast_atan2(y, x) - std::atan2(y, x));
      worst = std::max(worst, std::min(d, 2 * CV_PI - d));
    }
  }
  EXPECT_LT(worst, 2e-6);
}

}  // namespace
}  // namespace gvkit::capture
