// gray<B>-psp<N> and cgray<B>-psp<N>: N phase-shift images and B Gray-code images (MSB first)
// numbering the periods, optionally each followed by its inverse (complementary), optionally
// with white and black reference images, in any block order (PatternSpec::order). A plain bit is
// read against the mean of the white and black references when there are some, else against the
// phase-shift mean; a complementary bit is image > inverse, which needs no threshold and so does
// not care whether the code was seen as bright as the phase images. The period order is taken from
// the code at the period's centre, which tolerates code edges misplaced by up to half a period
// (blur, misregistration). A bit nearer its threshold than 0.7 of its nominal swing (the fringe
// modulation, the references' half difference, or for pairs the pixel's clearest pair) makes the
// pixel's code uncertain (camera noise on dark skin, hair, a blurred edge): it takes the period
// order of its certain neighbours instead (settle_uncertain), since one flipped bit moves the
// phase by whole periods.
#include <algorithm>
#include <cmath>
#include <string>

#include "gvkit/capture/phase_unwrapping.hpp"
#include "pattern_families.hpp"

namespace gvkit::capture::detail {
namespace {

// Where each image of a spec sits in the projected sequence.
struct ImageLayout {
  int phase = 0, white = -1, black = -1;
  std::vector<int> bit, inverse;  // per bit (MSB first); inverse empty unless complementary
};

ImageLayout layout_of(const PatternSpec& spec) {
  ImageLayout l;
  const int bits = spec.gray_bits;
  int at = 0;
  for (char block : spec.order) {
    switch (block) {
      case 'p':
        l.phase = at;
        at += spec.steps;
        break;
      case 'w':
        l.white = at++;
        break;
      case 'b':
        l.black = at++;
        break;
      case 'g':
        for (int b = 0; b < bits; ++b) {
          if (!spec.complementary) {
            l.bit.push_back(at + b);
          } else if (spec.inverses_after) {
            l.bit.push_back(at + b);
            l.inverse.push_back(at + bits + b);
          } else {
            l.bit.push_back(at + 2 * b);
            l.inverse.push_back(at + 2 * b + 1);
          }
        }
        at += bits * (spec.complementary ? 2 : 1);
        break;
    }
  }
  return l;
}

class GrayCodePattern : public PatternSet {
 public:
  GrayCodePattern(const PatternSpec& spec, const PatternSetOptions& o)
      : PatternSet(o),
        spec_(spec),
        convention_(FringeConvention::of(spec)),
        layout_(layout_of(spec)) {}

  std::string name() const override { return spec_.name(); }
  int image_count() const override { return spec_.image_count(); }
  bool absolute() const override { return true; }
  double pitch_px(int projector_width) const override {
    if (spec_.pitch_px > 0) return spec_.pitch_px;
    if (!spec_.periods.empty()) return static_cast<double>(projector_width) / spec_.periods[0];
    return static_cast<double>(projector_width) / (1 << spec_.gray_bits);
  }

  std::vector<cv::Mat> generate(cv::Size size) const override {
    const double pitch = pitch_px(size.width);
    const int bits = spec_.gray_bits;
    std::vector<cv::Mat> images(image_count());
    const std::vector<cv::Mat> phase = phase_shift_images(size, pitch, spec_.steps, convention_);
    for (int k = 0; k < spec_.steps; ++k) images[layout_.phase + k] = phase[k];
    if (layout_.white >= 0) images[layout_.white] = cv::Mat(size, CV_32F, cv::Scalar(1));
    if (layout_.black >= 0) images[layout_.black] = cv::Mat(size, CV_32F, cv::Scalar(0));
    for (int b = 0; b < bits; ++b) {
      cv::Mat row(1, size.width, CV_32F);
      for (int u = 0; u < size.width; ++u) {
        const int stripe = std::min((1 << bits) - 1, static_cast<int>(std::floor(u / pitch)));
        const int gray = stripe ^ (stripe >> 1);
        row.at<float>(u) = ((gray >> (bits - 1 - b)) & 1) ? 1.0f : 0.0f;
      }
      images[layout_.bit[b]] = cv::repeat(row, size.height, 1);
      if (spec_.complementary) images[layout_.inverse[b]] = 1.0 - images[layout_.bit[b]];
    }
    return images;
  }

  Result<PhaseMap> decode(const FringeSet& fringes, int projector_width) const override {
    GVKIT_RETURN_IF_ERROR(check_fringes(fringes, image_count(), name()));
    const int periods =
        static_cast<int>(std::ceil(projector_width / pitch_px(projector_width) - 1e-9));
    if (periods > (1 << spec_.gray_bits))
      return invalid_argument("pattern set " + name() + ": " + std::to_string(spec_.gray_bits) +
                              " bits number " + std::to_string(1 << spec_.gray_bits) +
                              " periods, but a " + std::to_string(projector_width) +
                              "-column projector holds " + std::to_string(periods) +
                              " at this pitch; more bits are needed");
    WrappedPhase w = decode_steps(fringes.images, layout_.phase, spec_.steps, options_);
    apply_convention(w, convention_);
    cv::Mat valid = valid_from(w, options_);
    const double range = fringes.images[0].depth() == CV_16U ? 65535.0 : 255.0;
    auto as_float = [&](int index) {
      cv::Mat f;
      fringes.images[index].convertTo(f, CV_32F, 1.0 / range);
      return f;
    };
    // Threshold and nominal swing of a plain bit: the references' mean and half their
    // difference, else the phase-shift mean and modulation.
    cv::Mat threshold = w.mean, swing = w.modulation;
    if (layout_.white >= 0) {
      const cv::Mat white = as_float(layout_.white), black = as_float(layout_.black);
      threshold = 0.5 * (white + black);
      swing = 0.5 * (white - black);
      valid &= swing >= static_cast<float>(options_.min_modulation);
    }
    const int bits = spec_.gray_bits;
    std::vector<cv::Mat> bit_images(bits), inverse_images(spec_.complementary ? bits : 0);
    for (int b = 0; b < bits; ++b) {
      bit_images[b] = as_float(layout_.bit[b]);
      if (spec_.complementary) inverse_images[b] = as_float(layout_.inverse[b]);
    }
    const float two_pi = static_cast<float>(2 * CV_PI);
    cv::Mat absolute(w.phase.size(), CV_32F);
    cv::Mat uncertain(w.phase.size(), CV_8U, cv::Scalar(0));
    for (int y = 0; y < absolute.rows; ++y) {
      const float* phase = w.phase.ptr<float>(y);
      const float* mean = threshold.ptr<float>(y);
      const float* nominal = swing.ptr<float>(y);
      uint8_t* ok = valid.ptr<uint8_t>(y);
      uint8_t* unsure = uncertain.ptr<uint8_t>(y);
      float* abs = absolute.ptr<float>(y);
      for (int x = 0; x < absolute.cols; ++x) {
        if (!ok[x]) {
          abs[x] = NAN;
          continue;
        }
        // A complementary pair is its own reference: its nominal swing is that of the pixel's
        // clearest pair (every pair sees the same surface and light).
        float d[12], full = nominal[x];
        for (int b = 0; b < bits; ++b) {
          const float level = bit_images[b].ptr<float>(y)[x];
          d[b] = spec_.complementary ? level - inverse_images[b].ptr<float>(y)[x] : level - mean[x];
        }
        if (spec_.complementary) {
          full = 0;
          for (int b = 0; b < bits; ++b) full = std::max(full, std::abs(d[b]));
        }
        int gray = 0;
        for (int b = 0; b < bits; ++b) {
          gray = (gray << 1) | (d[b] > 0 ? 1 : 0);
          if (std::abs(d[b]) < 0.7f * full) unsure[x] = 1;
        }
        int stripe = 0;
        for (int g = gray; g; g >>= 1) stripe ^= g;
        // Period order: the one whose centre is nearest; a tie (phase exactly 0 at the start of
        // a period) belongs to this period, hence ceil(x - 0.5) rather than rounding to even.
        const float centre = two_pi * (static_cast<float>(stripe) + 0.5f);
        abs[x] = phase[x] + two_pi * std::ceil((centre - phase[x]) / two_pi - 0.5f);
      }
    }
    return absolute_phase_map(absolute, valid, uncertain, w, pitch_px(projector_width),
                              projector_width);
  }

 private:
  PatternSpec spec_;
  FringeConvention convention_;
  ImageLayout layout_;
};

}  // namespace

std::unique_ptr<PatternSet> make_gray_code(const PatternSpec& spec, const PatternSetOptions& o) {
  return std::make_unique<GrayCodePattern>(spec, o);
}

}  // namespace gvkit::capture::detail
