// mf<N>-f<P1>-...-f1: N-step phase shift at 2 or 3 frequencies, finest first, unwrapped
// temporally from the one-period phase upwards (hierarchical temporal unwrapping).
#include <string>

#include "gvkit/capture/phase_unwrapping.hpp"
#include "pattern_families.hpp"

namespace gvkit::capture::detail {
namespace {

class MultiFrequencyPattern : public PatternSet {
 public:
  MultiFrequencyPattern(const PatternSpec& spec, const PatternSetOptions& o)
      : PatternSet(o),
        spec_(spec),
        convention_(FringeConvention::of(spec)),
        steps_(spec.steps),
        periods_(spec.periods) {}

  std::string name() const override { return spec_.name(); }
  int image_count() const override { return steps_ * static_cast<int>(periods_.size()); }
  bool absolute() const override { return true; }
  double pitch_px(int projector_width) const override {
    return static_cast<double>(projector_width) / periods_.front();
  }

  std::vector<cv::Mat> generate(cv::Size size) const override {
    std::vector<cv::Mat> images;
    for (int p : periods_)
      for (const cv::Mat& image :
           phase_shift_images(size, static_cast<double>(size.width) / p, steps_, convention_))
        images.push_back(image);
    return images;
  }

  Result<PhaseMap> decode(const FringeSet& fringes, int projector_width) const override {
    GVKIT_RETURN_IF_ERROR(check_fringes(fringes, image_count(), name()));
    const int levels = static_cast<int>(periods_.size());
    std::vector<WrappedPhase> w;
    for (int i = 0; i < levels; ++i) {
      w.push_back(decode_steps(fringes.images, i * steps_, steps_, options_));
      apply_convention(w.back(), convention_);
    }
    cv::Mat valid = valid_from(w[0], options_);
    for (int i = 1; i < levels; ++i) valid &= valid_from(w[i], options_);
    cv::Mat absolute = absolute_single_period(w[levels - 1].phase, valid);
    cv::Mat uncertain;
    for (int i = levels - 2; i >= 0; --i)
      absolute =
          unwrap_temporal(i == levels - 2 ? smoothed_single_period(absolute, valid) : absolute,
                          static_cast<double>(periods_[i]) / periods_[i + 1], w[i].phase,
                          options_.unwrap_tolerance, valid, &uncertain);
    return absolute_phase_map(absolute, valid, uncertain, w[0], pitch_px(projector_width),
                              projector_width);
  }

 private:
  PatternSpec spec_;
  FringeConvention convention_;
  int steps_;
  std::vector<int> periods_;
};

}  // namespace

std::unique_ptr<PatternSet> make_multi_frequency(const PatternSpec& spec,
                                                 const PatternSetOptions& o) {
  return std::make_unique<MultiFrequencyPattern>(spec, o);
}

}  // namespace gvkit::capture::detail
