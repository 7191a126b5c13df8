// Spatial and temporal unwrapping on known phase.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "gvkit/capture/phase_unwrapping.hpp"

namespace gvkit::capture {
namespace {

constexpr int kW = 160, kH = 120;

double true_phase(int x, int y) { return 0.35 * x + 0.1 * y + 3.0 * std::sin(x / 17.0); }

float wrap(double phi) { return static_cast<float>(std::remainder(phi, 2 * CV_PI)); }

struct Field {
  cv::Mat wrapped, quality, valid;
};

// Two regions (a main area with a hole, and an island) and a 3-pixel speck.
Field make_field() {
  Field f;
  f.wrapped.create(kH, kW, CV_32F);
  f.quality.create(kH, kW, CV_32F);
  f.valid = cv::Mat(kH, kW, CV_8U, cv::Scalar(255));
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      f.wrapped.at<float>(y, x) = wrap(true_phase(x, y));
      f.quality.at<float>(y, x) = static_cast<float>(0.2 + 0.1 * std::cos(x / 9.0 + y / 7.0));
    }
  cv::circle(f.valid, {60, 60}, 20, cv::Scalar(0), cv::FILLED);                // hole
  cv::rectangle(f.valid, {120, 0}, {124, kH - 1}, cv::Scalar(0), cv::FILLED);  // cut: island
  cv::rectangle(f.valid, {100, 100}, {108, 108}, cv::Scalar(0), cv::FILLED);
  f.valid.at<uint8_t>(104, 104) = 255;  // speck, dropped as too small
  return f;
}

void expect_unwrapped(const SpatialUnwrap& u, const cv::Mat& valid) {
  EXPECT_EQ(u.region_count, 2);
  EXPECT_EQ(valid.at<uint8_t>(104, 104), 0) << "small region must be dropped";
  EXPECT_TRUE(std::isnan(u.phase.at<float>(104, 104)));
  std::vector<double> offset(u.region_count + 1, NAN);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const int r = u.region.at<int>(y, x);
      if (!r) continue;
      const double d = u.phase.at<float>(y, x) - true_phase(x, y);
      if (std::isnan(offset[r])) {
        offset[r] = d;
        EXPECT_NEAR(std::remainder(d, 2 * CV_PI), 0.0, 1e-3);
      }
      ASSERT_NEAR(d, offset[r], 1e-3) << "at " << x << "," << y;
    }
}

TEST(SpatialUnwrap, QualityGuidedRecoversKnownPhase) {
  Field f = make_field();
  const SpatialUnwrap u = unwrap_quality_guided(f.wrapped, f.quality, f.valid, 10);
  expect_unwrapped(u, f.valid);
}

TEST(SpatialUnwrap, ReferenceRecoversKnownPhaseAndMatchesFast) {
  Field f = make_field(), g = make_field();
  const SpatialUnwrap ref = unwrap_quality_guided_reference(f.wrapped, f.quality, f.valid, 10);
  expect_unwrapped(ref, f.valid);
  const SpatialUnwrap fast = unwrap_quality_guided(g.wrapped, g.quality, g.valid, 10);
  // Seeds may differ (bucketed vs exact quality), so regions may differ by whole periods; within
  // a region the two must agree to a constant.
  EXPECT_EQ(ref.region_count, fast.region_count);
  std::vector<double> offset(ref.region_count + 1, NAN);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const float a = ref.phase.at<float>(y, x), b = fast.phase.at<float>(y, x);
      if (std::isnan(a) || std::isnan(b)) {
        EXPECT_EQ(std::isnan(a), std::isnan(b));
        continue;
      }
      const int r = ref.region.at<int>(y, x);
      if (std::isnan(offset[r])) offset[r] = a - b;
      ASSERT_NEAR(a - b, offset[r], 1e-3);
    }
}

TEST(SpatialUnwrap, NothingValidGivesNoRegion) {
  Field f = make_field();
  f.valid.setTo(0);
  const SpatialUnwrap u = unwrap_quality_guided(f.wrapped, f.quality, f.valid, 10);
  EXPECT_EQ(u.region_count, 0);
  EXPECT_EQ(cv::countNonZero(u.region), 0);
}

TEST(TemporalUnwrap, FromCoarsePhase) {
  const int periods = 16;
  cv::Mat coarse_wrapped(1, 900, CV_32F), fine_wrapped(1, 900, CV_32F);
  for (int x = 0; x < 900; ++x) {
    const double phi = 2 * CV_PI * x / 900.0;
    coarse_wrapped.at<float>(x) = wrap(phi + 0.02 * std::sin(x));  // noisy coarse phase
    fine_wrapped.at<float>(x) = wrap(phi * periods);
  }
  cv::Mat valid(1, 900, CV_8U, cv::Scalar(255));
  const cv::Mat coarse = absolute_single_period(coarse_wrapped, valid);
  const cv::Mat fine = unwrap_temporal(coarse, periods, fine_wrapped, 0.3, valid);
  for (int x = 5; x < 895; ++x) {
    ASSERT_TRUE(valid.at<uint8_t>(x));
    ASSERT_NEAR(fine.at<float>(x), 2 * CV_PI * periods * x / 900.0, 1e-3) << x;
  }
  // A coarse phase off by half a fine period is inconsistent: rejected.
  cv::Mat bad = coarse.clone();
  bad.at<float>(450) += static_cast<float>(CV_PI / periods);
  cv::Mat valid2(1, 900, CV_8U, cv::Scalar(255));
  unwrap_temporal(bad, periods, fine_wrapped, 0.3, valid2);
  EXPECT_EQ(valid2.at<uint8_t>(450), 0);
}

}  // namespace
}  // namespace gvkit::capture
