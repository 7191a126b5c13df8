// psp<N>-f<P>: N-step phase shift at one frequency, unwrapped spatially.
#include <string>

#include "pattern_families.hpp"

namespace gvkit::capture::detail {
namespace {

class PhaseShiftPattern : public PatternSet {
 public:
  PhaseShiftPattern(int steps, int periods, const PatternSetOptions& o)
      : PatternSet(o), steps_(steps), periods_(periods) {}

  std::string name() const override {
    return "psp" + std::to_string(steps_) + "-f" + std::to_string(periods_);
  }
  int image_count() const override { return steps_; }
  double pitch_px(int projector_width) const override {
    return static_cast<double>(projector_width) / periods_;
  }

  std::vector<cv::Mat> generate(cv::Size size) const override {
    std::vector<cv::Mat> images;
    for (int k = 0; k < steps_; ++k)
      images.push_back(cosine_image(size, pitch_px(size.width), 2 * CV_PI * k / steps_));
    return images;
  }

  Result<PhaseMap> decode(const FringeSet& fringes, int projector_width) const override {
    GVKIT_RETURN_IF_ERROR(check_fringes(fringes, steps_, name()));
    const WrappedPhase w = decode_steps(fringes.images, 0, steps_, options_);
    return spatially_unwrapped(w, pitch_px(projector_width), valid_from(w, options_), options_);
  }

 private:
  int steps_, periods_;
};

}  // namespace

std::unique_ptr<PatternSet> make_phase_shift(int steps, int periods, const PatternSetOptions& o) {
  return std::make_unique<PhaseShiftPattern>(steps, periods, o);
}

}  // namespace gvkit::capture::detail
