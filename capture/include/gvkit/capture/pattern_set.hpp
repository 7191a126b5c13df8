#pragma once
// PatternSet: one family of projected fringe patterns (generation and decoding) behind one
// interface. Every pattern varies along projector columns (vertical fringes); decoding turns the
// camera images of one instant into the projector column u seen by each camera pixel, in the
// projector's pixel coordinates (column c's centre is u = c).
//
// Names (create()):
//   psp<N>-f<P>             N-step phase shift (N >= 3), P periods across the projector width;
//                           spatial quality-guided unwrapping (phase known up to 2*pi per region)
//   mf<N>-f<P1>-f<P2>[-f<P3>]  multi-frequency temporal unwrapping, N shifts per frequency,
//                           finest first; the last frequency must be 1 period (absolute).
//                           mf3-f16-f1 is SLStudio's 2x3 scheme (the real skull data).
//   het<N>-f<P1>-f<P2>[-f<P3>] multi-frequency heterodyne, N shifts per frequency, finest first:
//                           the beats P1-P2 (and P2-P3) are unwrapped from the beat of the beats,
//                           which must be one period: P1-P2 = 1, or (P1-P2)-(P2-P3) = +-1
//                           (het4-f70-f64-f59: beats 6 and 5, their beat 1) (absolute)
//   zh-f<P>                 Zhang-Huang 2+1: two fringes 90 degrees apart + one flat image;
//                           spatial unwrapping
//   gray<B>-psp<N>          B Gray-code bit images + N-step phase shift with 2^B periods
//                           (absolute); bits read against the phase-shift mean (or the mean of
//                           the white and black references)
//   cgray<B>-psp<N>         complementary Gray code: each bit image followed by its inverse,
//                           bit = image > inverse (immune to the threshold's bias) (absolute)
// Gray-code modifiers, in this order: -f<P> (P periods: pitch = width / P) or -p<PX> (pitch in
// projector px; the code stripes are one pitch wide), -o<ORDER> (projection order of the blocks
// p phase, g gray, w white, b black; default pg; e.g. -owbgp), -ia (complementary: all bits,
// then all inverses). Every family but zh: -pos (image k shows phi + 2*pi*k/N instead of
// phi - 2*pi*k/N), -ph<DEG> (phi at column 0). Names with every modifier: cgray5-psp4-p40-owbgp-
// ia-pos-ph90. A JSON spec file (pattern_spec.hpp) says the same in words.
// Projected intensity of an N-step image k: I = 0.5 * (1 + cos(2*pi*u/p - 2*pi*k/N)).

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/capture/pattern_spec.hpp"
#include "gvkit/core/fringe_set.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

// Decoding thresholds, shared by every family. Intensities are normalised to [0, 1] by the
// image type's range (CV_8U: 255, CV_16U: 65535) before these apply.
struct PatternSetOptions {
  double min_modulation = 0.02;     // fringe amplitude below this -> invalid (shadow, dark)
  double saturation_level = 0.995;  // any image at or above this -> invalid (clipped)
  double unwrap_tolerance = 0.3;    // temporal unwrapping: max distance of the period estimate
                                    // from an integer (periods) before the pixel is rejected
  int min_region_px = 64;           // spatial unwrapping: smaller connected regions are dropped
  bool reference = false;           // use the plain (slow) decoding kernels

  Status check() const;
};

// Result of decoding one FringeSet.
struct PhaseMap {
  cv::Mat phase;    // CV_32F, unwrapped phase of the finest pattern (rad); NaN where invalid
  cv::Mat quality;  // CV_32F, fringe modulation of the finest pattern, in [0, 1]
  cv::Mat texture;  // CV_32F, mean intensity in [0, 1]
  cv::Mat valid;    // CV_8U, 255 where phase is usable
  cv::Mat region;   // CV_32S, region label (1..n) when !absolute, 0 = none; empty when absolute
  int region_count = 0;
  double pitch_px = 0;   // projector pixels per 2*pi of `phase`: u = phase / (2*pi) * pitch_px
  bool absolute = true;  // false: each region's phase is known only up to a multiple of 2*pi
};

class PatternSet {
 public:
  virtual ~PatternSet() = default;

  // Canonical name (as accepted by create()).
  virtual std::string name() const = 0;
  // Number of projected images (= camera images per FringeSet).
  virtual int image_count() const = 0;
  // Projector pixels per period of the finest pattern, for a projector of the given width.
  virtual double pitch_px(int projector_width) const = 0;
  // Whether decoding gives absolute phase (temporal unwrapping, Gray code), not phase known only
  // up to whole periods per region (spatial unwrapping).
  virtual bool absolute() const = 0;

  // The projector images for a projector of the given size: CV_32F in [0, 1] (linear intensity;
  // apply a gamma LUT before sending them to a real projector).
  virtual std::vector<cv::Mat> generate(cv::Size projector_size) const = 0;

  // Decodes the camera images of one instant. projector_width is the width the patterns were
  // generated for. Fails naming the image on a wrong count, mixed sizes or types, or NaNs.
  virtual Result<PhaseMap> decode(const FringeSet& fringes, int projector_width) const = 0;

  const PatternSetOptions& options() const { return options_; }

 protected:
  explicit PatternSet(PatternSetOptions options) : options_(options) {}
  PatternSetOptions options_;
};

// Makes a pattern set from its name (see above) or from a JSON spec file (a name ending in
// .json). Fails naming the name or file when it does not parse or a parameter is out of range.
Result<std::unique_ptr<PatternSet>> create_pattern_set(const std::string& name,
                                                       const PatternSetOptions& options = {});
Result<std::unique_ptr<PatternSet>> create_pattern_set(const PatternSpec& spec,
                                                       const PatternSetOptions& options = {});

// One line per family with an example, for --help texts.
std::string pattern_set_help();

// Names (with placeholders such as <P> for free parameters) of the pattern sets that project
// exactly `images` images per frame, most common first; empty when none does. For the message
// that asks a user with a plain folder of images to name its pattern set.
std::vector<std::string> pattern_set_candidates(int images);

// Projector column u (px) from an unwrapped phase map: u = phase / (2*pi) * pitch_px.
cv::Mat projector_column(const PhaseMap& phase);

}  // namespace gvkit::capture
