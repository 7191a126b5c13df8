#pragma once
// Internal: constructors of the pattern families and helpers they share (pattern_set.cpp).

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/pattern_spec.hpp"
#include "gvkit/capture/phase_shift.hpp"

namespace gvkit::capture::detail {

// Constructors per family; the spec has been checked (PatternSpec::check()).
std::unique_ptr<PatternSet> make_phase_shift(const PatternSpec& spec, const PatternSetOptions& o);
std::unique_ptr<PatternSet> make_multi_frequency(const PatternSpec& spec,
                                                 const PatternSetOptions& o);
std::unique_ptr<PatternSet> make_heterodyne(const PatternSpec& spec, const PatternSetOptions& o);
std::unique_ptr<PatternSet> make_zhang_huang(const PatternSpec& spec, const PatternSetOptions& o);
std::unique_ptr<PatternSet> make_gray_code(const PatternSpec& spec, const PatternSetOptions& o);

// The phase-shift convention of a spec: image k of N shows
// 0.5 * (1 + cos(2 pi u / pitch + offset_rad + sign * 2 pi k / N)).
struct FringeConvention {
  int sign = -1;
  double offset_rad = 0;
  static FringeConvention of(const PatternSpec& spec) {
    return {spec.shift_sign, spec.phase_offset_deg * CV_PI / 180};
  }
  bool is_default() const { return sign == -1 && offset_rad == 0; }
};

// The N images of one frequency (pitch_px per period) under a convention, CV_32F.
std::vector<cv::Mat> phase_shift_images(cv::Size size, double pitch_px, int steps,
                                        const FringeConvention& convention);
// Turns a phase decoded under SLStudio's convention into 2 pi u / pitch (wrapped to
// (-pi, pi]) for another convention; nothing to do for the default.
void apply_convention(WrappedPhase& w, const FringeConvention& convention);

// Wraps an angle to (-pi, pi].
inline float wrap_pi(float a) {
  const float two_pi = static_cast<float>(2 * CV_PI);
  a -= two_pi * std::floor(a / two_pi);  // [0, 2 pi)
  return a > static_cast<float>(CV_PI) ? a - two_pi : a;
}

// The one-period absolute phase, averaged over valid neighbours (Gaussian, sigma 1.5 px) as an
// angle, before a frequency ratio multiplies its noise. NaN where invalid.
cv::Mat smoothed_single_period(const cv::Mat& absolute, const cv::Mat& valid);

// Ok when fringes has `count` images of one size and one 8/16-bit type; names the image.
Status check_fringes(const FringeSet& fringes, int count, const std::string& pattern_name);

// 0.5 * (1 + cos(2*pi*u/pitch - shift)) for every projector column u, CV_32F.
cv::Mat cosine_image(cv::Size size, double pitch_px, double shift_rad);

// Runs the fast or the reference phase-shift kernel per options.reference.
WrappedPhase decode_steps(const std::vector<cv::Mat>& images, int first, int steps,
                          const PatternSetOptions& options);

// valid = modulation >= min_modulation and not saturated (and finite phase).
cv::Mat valid_from(const WrappedPhase& w, const PatternSetOptions& options);

// Fills a PhaseMap from a spatially unwrapped single-frequency decode.
PhaseMap spatially_unwrapped(const WrappedPhase& w, double pitch_px, cv::Mat valid,
                             const PatternSetOptions& options);

// Fills a PhaseMap from an absolute phase of the finest pattern `finest` (pitch_px per period,
// temporally unwrapped or numbered by a code): settles the `uncertain` pixels (CV_8U, may be
// empty), corrects isolated period-order errors and clears pixels that map outside the
// projector's `projector_width` columns.
PhaseMap absolute_phase_map(cv::Mat absolute, cv::Mat valid, const cv::Mat& uncertain,
                            const WrappedPhase& finest, double pitch_px, int projector_width);

}  // namespace gvkit::capture::detail
