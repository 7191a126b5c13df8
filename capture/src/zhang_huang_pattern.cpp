// zh-f<P>: Zhang-Huang 2+1 phase shifting. Image 0 = 0.5(1 + sin phi), image 1 = 0.5(1 + cos phi),
// image 2 = flat 0.5; the flat image gives the texture and the fringe offset directly, which
// makes the pair of fringes less sensitive to motion than three shifted fringes.
#include <cmath>
#include <string>

#include "pattern_families.hpp"

namespace gvkit::capture::detail {
namespace {

class ZhangHuangPattern : public PatternSet {
 public:
  ZhangHuangPattern(int periods, const PatternSetOptions& o) : PatternSet(o), periods_(periods) {}

  std::string name() const override { return "zh-f" + std::to_string(periods_); }
  int image_count() const override { return 3; }
  bool absolute() const override { return false; }
  double pitch_px(int projector_width) const override {
    return static_cast<double>(projector_width) / periods_;
  }

  std::vector<cv::Mat> generate(cv::Size size) const override {
    const double p = pitch_px(size.width);
    return {cosine_image(size, p, CV_PI / 2), cosine_image(size, p, 0),
            cv::Mat(size, CV_32F, cv::Scalar(0.5))};
  }

  Result<PhaseMap> decode(const FringeSet& fringes, int projector_width) const override {
    GVKIT_RETURN_IF_ERROR(check_fringes(fringes, 3, name()));
    const cv::Size size = fringes.size();
    WrappedPhase w;
    w.phase.create(size, CV_32F);
    w.modulation.create(size, CV_32F);
    w.mean.create(size, CV_32F);
    w.saturated.create(size, CV_8U);
    cv::Mat im[3];
    const double range = fringes.images[0].depth() == CV_16U ? 65535.0 : 255.0;
    for (int k = 0; k < 3; ++k) fringes.images[k].convertTo(im[k], CV_32F, 1.0 / range);
    const float sat = static_cast<float>(options_.saturation_level - 1e-7);
    for (int y = 0; y < size.height; ++y) {
      const float* i1 = im[0].ptr<float>(y);
      const float* i2 = im[1].ptr<float>(y);
      const float* i3 = im[2].ptr<float>(y);
      for (int x = 0; x < size.width; ++x) {
        const float s = i1[x] - i3[x], c = i2[x] - i3[x];
        w.phase.at<float>(y, x) =
            options_.reference ? static_cast<float>(std::atan2(s, c)) : fast_atan2(s, c);
        w.modulation.at<float>(y, x) = std::sqrt(s * s + c * c);
        w.mean.at<float>(y, x) = i3[x];
        w.saturated.at<uint8_t>(y, x) = (i1[x] >= sat || i2[x] >= sat || i3[x] >= sat) ? 255 : 0;
      }
    }
    return spatially_unwrapped(w, pitch_px(projector_width), valid_from(w, options_), options_);
  }

 private:
  int periods_;
};

}  // namespace

std::unique_ptr<PatternSet> make_zhang_huang(const PatternSpec& spec, const PatternSetOptions& o) {
  return std::make_unique<ZhangHuangPattern>(spec.periods[0], o);
}

}  // namespace gvkit::capture::detail
