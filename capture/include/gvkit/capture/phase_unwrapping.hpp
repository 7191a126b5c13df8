#pragma once
// Phase unwrapping: spatial (quality-guided, for single-frequency pattern sets) and temporal
// (from a coarser absolute phase, for multi-frequency sets).

#include <opencv2/core.hpp>

namespace gvkit::capture {

struct SpatialUnwrap {
  cv::Mat phase;   // CV_32F unwrapped phase, NaN outside regions
  cv::Mat region;  // CV_32S region label 1..region_count, 0 = none
  int region_count = 0;
};

// Quality-guided path-following unwrapping: starting at the best pixel of each connected region
// of `valid`, pixels are unwrapped against the neighbour (4-connected) that reaches them along
// the highest-quality path. wrapped, quality: CV_32F; valid: CV_8U (255 = usable), updated in
// place: regions smaller than min_region_px are cleared. Each region's result is relative: its
// seed keeps its wrapped value. Quality is bucketed into 64 levels (a bucket queue: linear time).
SpatialUnwrap unwrap_quality_guided(const cv::Mat& wrapped, const cv::Mat& quality, cv::Mat& valid,
                                    int min_region_px);
// The plain reference: an exact priority queue on quality. Same contract and, on consistent
// phase, the same result.
SpatialUnwrap unwrap_quality_guided_reference(const cv::Mat& wrapped, const cv::Mat& quality,
                                              cv::Mat& valid, int min_region_px);

// Temporal unwrapping of `fine_wrapped` (CV_32F, (-pi, pi]) against an absolute coarser phase
// (CV_32F) whose pattern has `ratio` times fewer periods: the period order is
// round((coarse * ratio - fine) / 2pi). Pixels whose estimate is further than `tolerance`
// periods from an integer, or that are invalid, are cleared in `valid` and set NaN.
cv::Mat unwrap_temporal(const cv::Mat& coarse_absolute, double ratio, const cv::Mat& fine_wrapped,
                        double tolerance, cv::Mat& valid);

// Absolute phase of a one-period pattern: the wrapped phase moved to [0, 2pi).
cv::Mat absolute_single_period(const cv::Mat& wrapped, const cv::Mat& valid);

}  // namespace gvkit::capture
