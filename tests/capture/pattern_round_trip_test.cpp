// Every pattern family: generate -> "camera" (the projector image seen 1:1, with offset and
// contrast) -> decode; the decoded projector column must match the true column.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <opencv2/core.hpp>

#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/phase_shift.hpp"
#include "support/test_support.hpp"

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
// 0.039 % of the pixels a period off; after: 0.022 % and 0.009 %). Complementary pairs swing
// twice as far against sqrt(2) times the noise, so they are flagged uncertain less often, and
// fewer pixels at code edges are settled from their neighbours: 0.032 % (cgray4-psp4) and
// 0.009 % (cgray5-psp3 with references) are left.
TEST(GrayCode, NoisyDarkSurfaceKeepsThePeriodOrder) {
  for (const char* name : {"gray4-psp4", "gray5-psp3", "cgray4-psp4", "cgray5-psp3-owbgp"}) {
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
    EXPECT_LT(period_errors, name[0] == 'c' ? 0.0004 : 0.0003) << name;
  }
}

INSTANTIATE_TEST_SUITE_P(Families, RoundTrip,
                         ::testing::Values("psp3-f16", "psp4-f16", "psp8-f32", "mf3-f16-f1",
                                           "mf4-f16-f1", "mf3-f64-f8-f1", "zh-f16", "gray4-psp4",
                                           "gray5-psp3", "het4-f70-f64-f59", "het3-f16-f15",
                                           "het4-f32-f27-f23", "cgray4-psp4", "cgray5-psp4-p40",
                                           "cgray5-psp3-f24-owbgp-ia", "gray5-psp4-p35-owbpg",
                                           "psp4-f16-pos", "mf3-f16-f1-ph90",
                                           "cgray4-psp4-ogp-pos-ph90"));

TEST(PatternSet, NamesAndBadNames) {
  auto skull = create_pattern_set("mf3-f16-f1");
  ASSERT_TRUE(skull);
  EXPECT_EQ((*skull)->image_count(), 6);
  EXPECT_DOUBLE_EQ((*skull)->pitch_px(1824), 114.0);  // the SLStudio skull's fine pitch
  for (const char* bad : {"psp2-f16",
                          "psp3",
                          "mf3-f16-f2",
                          "mf3-f1-f16",
                          "zh-f0",
                          "gray0-psp3",
                          "nonsense",
                          "",
                          "het4-f70-f64-f60",
                          "het3-f16-f14",
                          "het3-f16",
                          "gray4-psp4-ia",
                          "cgray4-psp4-oxg",
                          "cgray4-psp4-owgp",
                          "psp4-f16-p40",
                          "zh-f16-pos",
                          "cgray3-psp4-f16",
                          "psp4-f16-ph400",
                          "cgray4-psp4-p40-f16",
                          "mf3-f16-f1-zz"}) {
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

TEST(PatternSet, SpecsAndNamesRoundTrip) {
  for (const char* name : {"psp3-f16", "het4-f70-f64-f59", "cgray5-psp4-p40-owbgp-ia-pos-ph90",
                           "gray4-psp4", "gray5-psp3-f24", "mf4-f16-f1-pos", "zh-f8"}) {
    auto spec = parse_pattern_name(name);
    ASSERT_TRUE(spec) << name << ": " << spec.status().message();
    EXPECT_EQ(spec->name(), name);
  }
  auto spec = parse_pattern_name("cgray5-psp4-p40-owbgp");
  ASSERT_TRUE(spec);
  EXPECT_EQ(spec->image_count(), 2 + 10 + 4);
  EXPECT_TRUE(spec->has_references());
  auto unknown = create_pattern_set("cgray5-psp4-p40-foo");
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.status().message().find("unknown part 'foo'"), std::string::npos)
      << unknown.status().message();
}

TEST(PatternSet, JsonSpecNamesTheSameSet) {
  testing::TempDir dir;
  const auto path = dir / "patterns.json";
  std::ofstream(path) << R"({"family": "gray-code", "gray_bits": 5, "complementary": true,
    "steps": 4, "pitch_px": 40, "order": ["white", "black", "gray", "phase"],
    "inverses": "after", "shift_sign": 1, "phase_offset_deg": 90,
    "comment": "our rig, 2024"})";
  auto set = create_pattern_set(path.string());
  ASSERT_TRUE(set) << set.status().message();
  EXPECT_EQ((*set)->name(), "cgray5-psp4-p40-owbgp-ia-pos-ph90");
  EXPECT_EQ((*set)->image_count(), 16);
  auto het = dir / "het.json";
  std::ofstream(het) << R"({"family": "heterodyne", "steps": 4, "periods": [70, 64, 59]})";
  auto h = create_pattern_set(het.string());
  ASSERT_TRUE(h) << h.status().message();
  EXPECT_EQ((*h)->name(), "het4-f70-f64-f59");
  // Mistakes name the file and the key.
  auto typo = dir / "typo.json";
  std::ofstream(typo) << R"({"family": "gray-code", "gray_bits": 5, "step": 4})";
  auto t = create_pattern_set(typo.string());
  ASSERT_FALSE(t);
  EXPECT_NE(t.status().message().find("typo.json: unknown key 'step'"), std::string::npos)
      << t.status().message();
  auto family = dir / "family.json";
  std::ofstream(family) << R"({"family": "moire"})";
  auto f = create_pattern_set(family.string());
  ASSERT_FALSE(f);
  EXPECT_NE(f.status().message().find("family 'moire'"), std::string::npos);
  EXPECT_FALSE(create_pattern_set((dir / "absent.json").string()));
}

// Gray images taken at 40 % of the phase images' brightness (the exposure or the projector's
// mode changed between the blocks): a plain bit read against the phase-shift mean is 0 everywhere,
// a complementary pair still compares like with like.
TEST(PatternSet, ComplementaryCodeNeedsNoThreshold) {
  ColumnError plain, complementary;
  for (const char* name : {"gray5-psp4", "cgray5-psp4"}) {
    auto set = create_pattern_set(name);
    ASSERT_TRUE(set);
    const std::vector<cv::Mat> patterns = (*set)->generate({kWidth, kRows});
    FringeSet f;
    for (size_t k = 0; k < patterns.size(); ++k) {
      const double gain = k < 4 ? 1.0 : 0.4;  // phase images first
      cv::Mat image;
      cv::Mat(gain * (0.05 + 0.9 * patterns[k])).convertTo(image, CV_16U, 65535.0);
      f.images.push_back(image);
    }
    auto map = (*set)->decode(f, kWidth);
    ASSERT_TRUE(map) << map.status().message();
    (std::string(name) == "cgray5-psp4" ? complementary : plain) = column_error(*map);
  }
  EXPECT_GT(complementary.valid_share, 0.99);
  EXPECT_EQ(complementary.period_error_share, 0.0);
  EXPECT_LT(complementary.rms, 0.01);
  EXPECT_TRUE(plain.valid_share < 0.5 || plain.period_error_share > 0.1)
      << plain.valid_share << " " << plain.period_error_share;
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
