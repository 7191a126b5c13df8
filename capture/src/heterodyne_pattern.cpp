// het<N>-f<P1>-f<P2>[-f<P3>]: N-step phase shift at 2 or 3 close frequencies, finest first,
// unwrapped by heterodyning. The difference of two wrapped phases is the wrapped phase of their
// beat, a fringe of P1 - P2 periods; with three frequencies the beat of the two beats
// (P1 - P2) - (P2 - P3) is one period across the projector, hence absolute. Unwrapping then
// climbs back: the beat of the beats unwraps the first beat, which unwraps the finest phase.
// Each step multiplies the coarser phase's noise by its frequency ratio (70/64/59: 6, then
// 70/6), which is why the one-period phase is smoothed first (as for mf).
#include <cmath>
#include <string>

#include "gvkit/capture/phase_unwrapping.hpp"
#include "pattern_families.hpp"

namespace gvkit::capture::detail {
namespace {

// Wrapped phase of a - b (both wrapped), NaN where either is.
cv::Mat wrapped_difference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat out(a.size(), CV_32F);
  for (int y = 0; y < a.rows; ++y) {
    const float* pa = a.ptr<float>(y);
    const float* pb = b.ptr<float>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < a.cols; ++x) o[x] = wrap_pi(pa[x] - pb[x]);
  }
  return out;
}

class HeterodynePattern : public PatternSet {
 public:
  HeterodynePattern(const PatternSpec& spec, const PatternSetOptions& o)
      : PatternSet(o), spec_(spec), convention_(FringeConvention::of(spec)) {}

  std::string name() const override { return spec_.name(); }
  int image_count() const override { return spec_.image_count(); }
  bool absolute() const override { return true; }
  double pitch_px(int projector_width) const override {
    return static_cast<double>(projector_width) / spec_.periods.front();
  }

  std::vector<cv::Mat> generate(cv::Size size) const override {
    std::vector<cv::Mat> images;
    for (int p : spec_.periods)
      for (const cv::Mat& image :
           phase_shift_images(size, static_cast<double>(size.width) / p, spec_.steps, convention_))
        images.push_back(image);
    return images;
  }

  Result<PhaseMap> decode(const FringeSet& fringes, int projector_width) const override {
    GVKIT_RETURN_IF_ERROR(check_fringes(fringes, image_count(), name()));
    const std::vector<int>& p = spec_.periods;
    std::vector<WrappedPhase> w;
    for (size_t i = 0; i < p.size(); ++i) {
      w.push_back(
          decode_steps(fringes.images, static_cast<int>(i) * spec_.steps, spec_.steps, options_));
      apply_convention(w.back(), convention_);
    }
    cv::Mat valid = valid_from(w[0], options_);
    for (size_t i = 1; i < w.size(); ++i) valid &= valid_from(w[i], options_);
    cv::Mat uncertain;
    cv::Mat beat = wrapped_difference(w[0].phase, w[1].phase);  // P1 - P2 periods
    int beat_periods = p[0] - p[1];
    if (p.size() == 3) {
      const cv::Mat beat23 = wrapped_difference(w[1].phase, w[2].phase);  // P2 - P3 periods
      const int b12 = p[0] - p[1], b23 = p[1] - p[2];
      // The beat of the beats: one period, absolute.
      const cv::Mat one =
          b12 > b23 ? wrapped_difference(beat, beat23) : wrapped_difference(beat23, beat);
      const cv::Mat one_absolute =
          smoothed_single_period(absolute_single_period(one, valid), valid);
      beat = unwrap_temporal(one_absolute, b12, beat, options_.unwrap_tolerance, valid, &uncertain);
    } else {
      beat = smoothed_single_period(absolute_single_period(beat, valid), valid);
    }
    cv::Mat absolute = unwrap_temporal(beat, static_cast<double>(p[0]) / beat_periods, w[0].phase,
                                       options_.unwrap_tolerance, valid, &uncertain);
    return absolute_phase_map(absolute, valid, uncertain, w[0], pitch_px(projector_width),
                              projector_width);
  }

 private:
  PatternSpec spec_;
  FringeConvention convention_;
};

}  // namespace

std::unique_ptr<PatternSet> make_heterodyne(const PatternSpec& spec, const PatternSetOptions& o) {
  return std::make_unique<HeterodynePattern>(spec, o);
}

}  // namespace gvkit::capture::detail
