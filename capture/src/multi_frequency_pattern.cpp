// mf<N>-f<P1>-...-f1: N-step phase shift at 2 or 3 frequencies, finest first, unwrapped
// temporally from the one-period phase upwards (hierarchical temporal unwrapping).
#include <cmath>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "gvkit/capture/phase_unwrapping.hpp"
#include "pattern_families.hpp"

namespace gvkit::capture::detail {
namespace {

// The one-period phase, averaged over valid neighbours (Gaussian, sigma 1.5 px) as an angle
// (cos and sin averaged, so the 0/2pi seam is harmless) before it is multiplied by the frequency
// ratio: its noise, not the fine phase's, decides the period order, and it is smooth wherever the
// surface is.
cv::Mat smoothed_single_period(const cv::Mat& absolute, const cv::Mat& valid) {
  cv::Mat weight, c(absolute.size(), CV_32F), s(absolute.size(), CV_32F);
  valid.convertTo(weight, CV_32F, 1.0 / 255);
  for (int y = 0; y < absolute.rows; ++y)
    for (int x = 0; x < absolute.cols; ++x) {
      const bool ok = valid.at<uint8_t>(y, x) != 0;
      const float phi = absolute.at<float>(y, x);
      c.at<float>(y, x) = ok ? std::cos(phi) : 0.0f;
      s.at<float>(y, x) = ok ? std::sin(phi) : 0.0f;
    }
  cv::GaussianBlur(c, c, cv::Size(7, 7), 1.5);
  cv::GaussianBlur(s, s, cv::Size(7, 7), 1.5);
  cv::Mat out(absolute.size(), CV_32F);
  const float two_pi = static_cast<float>(2 * CV_PI);
  for (int y = 0; y < out.rows; ++y)
    for (int x = 0; x < out.cols; ++x) {
      if (!valid.at<uint8_t>(y, x)) {
        out.at<float>(y, x) = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      const float phi = std::atan2(s.at<float>(y, x), c.at<float>(y, x));
      out.at<float>(y, x) = phi < 0 ? phi + two_pi : phi;
    }
  return out;
}

class MultiFrequencyPattern : public PatternSet {
 public:
  MultiFrequencyPattern(int steps, std::vector<int> periods, const PatternSetOptions& o)
      : PatternSet(o), steps_(steps), periods_(std::move(periods)) {}

  std::string name() const override {
    std::string n = "mf" + std::to_string(steps_);
    for (int p : periods_) n += "-f" + std::to_string(p);
    return n;
  }
  int image_count() const override { return steps_ * static_cast<int>(periods_.size()); }
  double pitch_px(int projector_width) const override {
    return static_cast<double>(projector_width) / periods_.front();
  }

  std::vector<cv::Mat> generate(cv::Size size) const override {
    std::vector<cv::Mat> images;
    for (int p : periods_)
      for (int k = 0; k < steps_; ++k)
        images.push_back(
            cosine_image(size, static_cast<double>(size.width) / p, 2 * CV_PI * k / steps_));
    return images;
  }

  Result<PhaseMap> decode(const FringeSet& fringes, int projector_width) const override {
    GVKIT_RETURN_IF_ERROR(check_fringes(fringes, image_count(), name()));
    const int levels = static_cast<int>(periods_.size());
    std::vector<WrappedPhase> w;
    for (int i = 0; i < levels; ++i)
      w.push_back(decode_steps(fringes.images, i * steps_, steps_, options_));
    cv::Mat valid = valid_from(w[0], options_);
    for (int i = 1; i < levels; ++i) valid &= valid_from(w[i], options_);
    cv::Mat absolute = absolute_single_period(w[levels - 1].phase, valid);
    cv::Mat uncertain;
    for (int i = levels - 2; i >= 0; --i)
      absolute =
          unwrap_temporal(i == levels - 2 ? smoothed_single_period(absolute, valid) : absolute,
                          static_cast<double>(periods_[i]) / periods_[i + 1], w[i].phase,
                          options_.unwrap_tolerance, valid, &uncertain);
    settle_uncertain(absolute, valid, uncertain);
    correct_period_order(absolute, valid);
    clear_outside_projector(absolute, valid, pitch_px(projector_width), projector_width);
    PhaseMap out;
    out.phase = absolute;
    out.quality = w[0].modulation;
    out.texture = w[0].mean;
    out.valid = valid;
    out.pitch_px = pitch_px(projector_width);
    out.absolute = true;
    return out;
  }

 private:
  int steps_;
  std::vector<int> periods_;
};

}  // namespace

std::unique_ptr<PatternSet> make_multi_frequency(int steps, std::vector<int> periods,
                                                 const PatternSetOptions& o) {
  return std::make_unique<MultiFrequencyPattern>(steps, std::move(periods), o);
}

}  // namespace gvkit::capture::detail
