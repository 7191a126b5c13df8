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
// seed keeps its wrapped value. Neighbours whose phases differ by more than 0.6 pi are not
// unwrapped against each other (a steep slope or a depth edge): regions split there, and
// the Reconstructor rejoins them by depth continuity. Quality is bucketed into 64 levels (a bucket
// queue: linear time).
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
// With `uncertain` (CV_8U, same size, accumulated with OR), such pixels keep their nearest
// period order and are flagged there instead, for settle_uncertain().
cv::Mat unwrap_temporal(const cv::Mat& coarse_absolute, double ratio, const cv::Mat& fine_wrapped,
                        double tolerance, cv::Mat& valid, cv::Mat* uncertain = nullptr);

// Gives each uncertain pixel the period order that puts it nearest the median of the certain
// valid pixels of its 5x5 neighbourhood (at least 4 of them); without enough of them the pixel
// is cleared. Returns the number of pixels kept.
int settle_uncertain(cv::Mat& absolute, cv::Mat& valid, const cv::Mat& uncertain);

// Corrects isolated period-order errors of an absolute phase map (CV_32F, NaN invalid) in place:
// a pixel that disagrees by more than pi with most of its 4 neighbours is moved by whole periods
// to the median of its valid 5x5 neighbourhood. Returns the number of corrected pixels.
int correct_period_order(cv::Mat& absolute, const cv::Mat& valid);

// Clears (NaN, invalid) pixels whose absolute phase maps outside the projector's columns
// [-0.5, width - 0.5], given pitch_px per period.
void clear_outside_projector(cv::Mat& absolute, cv::Mat& valid, double pitch_px, int width);

// Absolute phase of a one-period pattern: the wrapped phase moved to [0, 2pi).
cv::Mat absolute_single_period(const cv::Mat& wrapped, const cv::Mat& valid);

}  // namespace gvkit::capture
