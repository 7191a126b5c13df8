// psp<N>-f<P>: N-step phase shift at one frequency, unwrapped spatially.
#include <string>

#include "pattern_families.hpp"

namespace gvkit::capture::detail {
namespace {

class PhaseShiftPattern : public PatternSet {
 public:
  PhaseShiftPattern(const PatternSpec& spec, const PatternSetOptions& o)
      : PatternSet(o), spec_(spec), convention_(FringeConvention::of(spec)) {}

  std::string name() const override { return spec_.name(); }
  int image_count() const override { return spec_.steps; }
  bool absolute() const override { return false; }
  double pitch_px(int projector_width) const override {
    return static_cast<double>(projector_width) / spec_.periods[0];
  }

  std::vector<cv::Mat> generate(cv::Size size) const override {
    return phase_shift_images(size, pitch_px(size.width), spec_.steps, convention_);
  }

  Result<PhaseMap> decode(const FringeSet& fringes, int projector_width) const override {
    GVKIT_RETURN_IF_ERROR(check_fringes(fringes, spec_.steps, name()));
    WrappedPhase w = decode_steps(fringes.images, 0, spec_.steps, options_);
    apply_convention(w, convention_);
    return spatially_unwrapped(w, pitch_px(projector_width), valid_from(w, options_), options_);
  }

 private:
  PatternSpec spec_;
  FringeConvention convention_;
};

}  // namespace

std::unique_ptr<PatternSet> make_phase_shift(const PatternSpec& spec, const PatternSetOptions& o) {
  return std::make_unique<PhaseShiftPattern>(spec, o);
}

}  // namespace gvkit::capture::detail
