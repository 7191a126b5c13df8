// gray<B>-psp<N>: N phase-shift images with 2^B periods, then B Gray-code images (MSB first)
// numbering the periods. Bits are read against the phase-shift mean; the period order is taken
// from the code at the period's centre, which tolerates code edges misplaced by up to half a
// period (blur, misregistration). A bit nearer the mean than 0.7 of the fringe modulation (camera
// noise on dark skin, hair, a blurred edge) makes the pixel's code uncertain: it takes the period
// order of its certain neighbours instead (settle_uncertain), since one flipped bit moves the
// phase by whole periods.
#include <cmath>
#include <string>

#include "gvkit/capture/phase_unwrapping.hpp"
#include "pattern_families.hpp"

namespace gvkit::capture::detail {
namespace {

class GrayCodePattern : public PatternSet {
 public:
  GrayCodePattern(int bits, int steps, const PatternSetOptions& o)
      : PatternSet(o), bits_(bits), steps_(steps) {}

  std::string name() const override {
    return "gray" + std::to_string(bits_) + "-psp" + std::to_string(steps_);
  }
  int image_count() const override { return steps_ + bits_; }
  double pitch_px(int projector_width) const override {
    return static_cast<double>(projector_width) / (1 << bits_);
  }

  std::vector<cv::Mat> generate(cv::Size size) const override {
    const double pitch = pitch_px(size.width);
    std::vector<cv::Mat> images;
    for (int k = 0; k < steps_; ++k)
      images.push_back(cosine_image(size, pitch, 2 * CV_PI * k / steps_));
    for (int b = 0; b < bits_; ++b) {
      cv::Mat row(1, size.width, CV_32F);
      for (int u = 0; u < size.width; ++u) {
        const int stripe = std::min((1 << bits_) - 1, static_cast<int>(std::floor(u / pitch)));
        const int gray = stripe ^ (stripe >> 1);
        row.at<float>(u) = ((gray >> (bits_ - 1 - b)) & 1) ? 1.0f : 0.0f;
      }
      images.push_back(cv::repeat(row, size.height, 1));
    }
    return images;
  }

  Result<PhaseMap> decode(const FringeSet& fringes, int projector_width) const override {
    GVKIT_RETURN_IF_ERROR(check_fringes(fringes, image_count(), name()));
    const WrappedPhase w = decode_steps(fringes.images, 0, steps_, options_);
    cv::Mat valid = valid_from(w, options_);
    const double range = fringes.images[0].depth() == CV_16U ? 65535.0 : 255.0;
    std::vector<cv::Mat> bit_images(bits_);
    for (int b = 0; b < bits_; ++b)
      fringes.images[steps_ + b].convertTo(bit_images[b], CV_32F, 1.0 / range);
    const float two_pi = static_cast<float>(2 * CV_PI);
    cv::Mat absolute(w.phase.size(), CV_32F);
    cv::Mat uncertain(w.phase.size(), CV_8U, cv::Scalar(0));
    for (int y = 0; y < absolute.rows; ++y) {
      const float* phase = w.phase.ptr<float>(y);
      const float* mean = w.mean.ptr<float>(y);
      const float* modulation = w.modulation.ptr<float>(y);
      uint8_t* ok = valid.ptr<uint8_t>(y);
      uint8_t* unsure = uncertain.ptr<uint8_t>(y);
      float* abs = absolute.ptr<float>(y);
      for (int x = 0; x < absolute.cols; ++x) {
        if (!ok[x]) {
          abs[x] = NAN;
          continue;
        }
        int gray = 0;
        for (int b = 0; b < bits_; ++b) {
          const float level = bit_images[b].ptr<float>(y)[x];
          gray = (gray << 1) | (level > mean[x] ? 1 : 0);
          if (std::abs(level - mean[x]) < 0.7f * modulation[x]) unsure[x] = 1;
        }
        int stripe = 0;
        for (int g = gray; g; g >>= 1) stripe ^= g;
        // Period order: the one whose centre is nearest; a tie (phase exactly 0 at the start of
        // a period) belongs to this period, hence ceil(x - 0.5) rather than rounding to even.
        const float centre = two_pi * (static_cast<float>(stripe) + 0.5f);
        abs[x] = phase[x] + two_pi * std::ceil((centre - phase[x]) / two_pi - 0.5f);
      }
    }
    settle_uncertain(absolute, valid, uncertain);
    correct_period_order(absolute, valid);
    clear_outside_projector(absolute, valid, pitch_px(projector_width), projector_width);
    PhaseMap out;
    out.phase = absolute;
    out.quality = w.modulation;
    out.texture = w.mean;
    out.valid = valid;
    out.pitch_px = pitch_px(projector_width);
    out.absolute = true;
    return out;
  }

 private:
  int bits_, steps_;
};

}  // namespace

std::unique_ptr<PatternSet> make_gray_code(int bits, int steps, const PatternSetOptions& o) {
  return std::make_unique<GrayCodePattern>(bits, steps, o);
}

}  // namespace gvkit::capture::detail
