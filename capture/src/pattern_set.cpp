#include "gvkit/capture/pattern_set.hpp"

#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "gvkit/capture/phase_unwrapping.hpp"
#include "pattern_families.hpp"

namespace gvkit::capture {

Status PatternSetOptions::check() const {
  if (!(min_modulation >= 0 && min_modulation < 1))
    return invalid_argument("min_modulation must be in [0, 1), is " +
                            std::to_string(min_modulation));
  if (!(saturation_level > 0 && saturation_level <= 1))
    return invalid_argument("saturation_level must be in (0, 1], is " +
                            std::to_string(saturation_level));
  if (!(unwrap_tolerance > 0 && unwrap_tolerance < 0.5))
    return invalid_argument("unwrap_tolerance must be in (0, 0.5) periods, is " +
                            std::to_string(unwrap_tolerance));
  if (min_region_px < 1)
    return invalid_argument("min_region_px must be >= 1, is " + std::to_string(min_region_px));
  return Status::ok();
}

Result<std::unique_ptr<PatternSet>> create_pattern_set(const std::string& name,
                                                       const PatternSetOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  PatternSpec spec;
  if (name.size() > 5 && name.compare(name.size() - 5, 5, ".json") == 0) {
    GVKIT_ASSIGN_OR_RETURN(spec, read_pattern_spec(name));
  } else {
    Result<PatternSpec> parsed = parse_pattern_name(name);
    if (!parsed) {
      std::string message = parsed.status().message();
      if (message.find("unknown name") != std::string::npos)
        message += "; known: " + pattern_set_help() + "; or a SPEC.json file";
      return invalid_argument(message);
    }
    spec = *parsed;
  }
  return create_pattern_set(spec, options);
}

Result<std::unique_ptr<PatternSet>> create_pattern_set(const PatternSpec& spec,
                                                       const PatternSetOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  Status ok = spec.check();
  if (!ok) return ok.with_context("pattern set '" + spec.name() + "'");
  switch (spec.family) {
    case PatternSpec::Family::kPhaseShift:
      return detail::make_phase_shift(spec, options);
    case PatternSpec::Family::kMultiFrequency:
      return detail::make_multi_frequency(spec, options);
    case PatternSpec::Family::kHeterodyne:
      return detail::make_heterodyne(spec, options);
    case PatternSpec::Family::kZhangHuang:
      return detail::make_zhang_huang(spec, options);
    case PatternSpec::Family::kGrayCode:
      return detail::make_gray_code(spec, options);
  }
  return invalid_argument("pattern set '" + spec.name() + "': unknown family");
}

std::string pattern_set_help() {
  return "psp<N>-f<P> (N-step phase shift, P periods, spatial unwrapping; e.g. psp3-f16), "
         "mf<N>-f<P1>-f<P2>[-f<P3>] (multi-frequency temporal unwrapping, finest first, last f1; "
         "e.g. mf3-f16-f1 = the 2x3 skull scheme, mf4-f16-f1, mf3-f64-f8-f1), "
         "het<N>-f<P1>-f<P2>[-f<P3>] (multi-frequency heterodyne: beats unwrap, the beat of the "
         "beats is one period; e.g. het4-f70-f64-f59, het3-f16-f15), "
         "zh-f<P> (Zhang-Huang 2+1; e.g. zh-f16), "
         "gray<B>-psp<N> (B Gray-code bits + N-step phase shift with 2^B periods; e.g. "
         "gray4-psp4), "
         "cgray<B>-psp<N> (complementary Gray code: each bit and its inverse; e.g. cgray5-psp4); "
         "Gray codes take -f<P> (P periods) or -p<PX> (pitch in projector px), -o<ORDER> "
         "(projection order of p phase, g gray, w white, b black; default pg; e.g. -owbgp) and "
         "-ia (all inverses after the bits); every family but zh takes -pos (image k shifted by "
         "+2 pi k/N) and -ph<DEG> (phase of image 0)";
}

std::vector<std::string> pattern_set_candidates(int images) {
  std::vector<std::string> out;
  auto n = [](int v) { return std::to_string(v); };
  if (images >= 3 && images <= 64) out.push_back("psp" + n(images) + "-f<P>");
  if (images % 2 == 0 && images / 2 >= 3 && images / 2 <= 64)
    out.push_back("mf" + n(images / 2) + "-f<P>-f1");
  if (images % 3 == 0 && images / 3 >= 3 && images / 3 <= 64)
    out.push_back("mf" + n(images / 3) + "-f<P1>-f<P2>-f1");
  if (images % 2 == 0 && images / 2 >= 3 && images / 2 <= 64)
    out.push_back("het" + n(images / 2) + "-f<P>-f<P-1>");
  if (images % 3 == 0 && images / 3 >= 3 && images / 3 <= 64)
    out.push_back("het" + n(images / 3) + "-f<P1>-f<P2>-f<P3> (e.g. het" + n(images / 3) +
                  "-f70-f64-f59)");
  // Gray code + phase shift: the common splits (3 to 10 bits, 3 to 8 steps), most bits first;
  // complementary codes without and with white and black references.
  for (int bits = 10; bits >= 3; --bits)
    if (images - bits >= 3 && images - bits <= 8)
      out.push_back("gray" + n(bits) + "-psp" + n(images - bits));
  for (int refs = 0; refs <= 2; refs += 2)
    for (int bits = 10; bits >= 3; --bits) {
      const int steps = images - 2 * bits - refs;
      if (steps >= 3 && steps <= 8)
        out.push_back("cgray" + n(bits) + "-psp" + n(steps) + (refs ? "-owbpg" : ""));
    }
  if (images == 3) out.push_back("zh-f<P>");
  return out;
}

cv::Mat projector_column(const PhaseMap& phase) {
  cv::Mat u;
  phase.phase.convertTo(u, CV_32F, phase.pitch_px / (2 * CV_PI));
  return u;
}

namespace detail {

Status check_fringes(const FringeSet& fringes, int count, const std::string& pattern_name) {
  if (static_cast<int>(fringes.images.size()) != count)
    return invalid_argument("frame " + std::to_string(fringes.index) + ": pattern set " +
                            pattern_name + " needs " + std::to_string(count) + " images, got " +
                            std::to_string(fringes.images.size()));
  Status s = fringes.check();
  if (!s) return s.with_context("frame " + std::to_string(fringes.index));
  for (size_t i = 1; i < fringes.images.size(); ++i)
    if (fringes.images[i].depth() != fringes.images[0].depth())
      return invalid_argument("frame " + std::to_string(fringes.index) + ": image " +
                              std::to_string(i) + " has a different bit depth than image 0");
  return Status::ok();
}

std::vector<cv::Mat> phase_shift_images(cv::Size size, double pitch_px, int steps,
                                        const FringeConvention& c) {
  std::vector<cv::Mat> images;
  for (int k = 0; k < steps; ++k)
    images.push_back(cosine_image(size, pitch_px, -c.offset_rad - c.sign * 2 * CV_PI * k / steps));
  return images;
}

void apply_convention(WrappedPhase& w, const FringeConvention& c) {
  if (c.is_default()) return;
  // The kernel reads psi with images cos(psi - 2 pi k / N); here psi = -sign * (phi + offset).
  const float sign = static_cast<float>(-c.sign), offset = static_cast<float>(c.offset_rad);
  for (int y = 0; y < w.phase.rows; ++y) {
    float* phase = w.phase.ptr<float>(y);
    for (int x = 0; x < w.phase.cols; ++x)
      if (std::isfinite(phase[x])) phase[x] = wrap_pi(sign * phase[x] - offset);
  }
}

cv::Mat smoothed_single_period(const cv::Mat& absolute, const cv::Mat& valid) {
  cv::Mat c(absolute.size(), CV_32F), s(absolute.size(), CV_32F);
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

cv::Mat cosine_image(cv::Size size, double pitch_px, double shift_rad) {
  cv::Mat row(1, size.width, CV_32F);
  for (int u = 0; u < size.width; ++u)
    row.at<float>(u) =
        static_cast<float>(0.5 * (1 + std::cos(2 * CV_PI * u / pitch_px - shift_rad)));
  return cv::repeat(row, size.height, 1);
}

WrappedPhase decode_steps(const std::vector<cv::Mat>& images, int first, int steps,
                          const PatternSetOptions& options) {
  return options.reference
             ? decode_phase_shift_reference(images, first, steps, options.saturation_level)
             : decode_phase_shift(images, first, steps, options.saturation_level);
}

cv::Mat valid_from(const WrappedPhase& w, const PatternSetOptions& options) {
  cv::Mat valid(w.phase.size(), CV_8U);
  const float min_mod = static_cast<float>(options.min_modulation);
  for (int y = 0; y < valid.rows; ++y) {
    const float* m = w.modulation.ptr<float>(y);
    const uint8_t* sat = w.saturated.ptr<uint8_t>(y);
    uint8_t* ok = valid.ptr<uint8_t>(y);
    for (int x = 0; x < valid.cols; ++x) ok[x] = (m[x] >= min_mod && m[x] > 0 && !sat[x]) ? 255 : 0;
  }
  return valid;
}

PhaseMap spatially_unwrapped(const WrappedPhase& w, double pitch_px, cv::Mat valid,
                             const PatternSetOptions& options) {
  SpatialUnwrap u =
      options.reference
          ? unwrap_quality_guided_reference(w.phase, w.modulation, valid, options.min_region_px)
          : unwrap_quality_guided(w.phase, w.modulation, valid, options.min_region_px);
  PhaseMap out;
  out.phase = u.phase;
  out.quality = w.modulation;
  out.texture = w.mean;
  out.valid = valid;
  out.region = u.region;
  out.region_count = u.region_count;
  out.pitch_px = pitch_px;
  out.absolute = false;
  return out;
}

PhaseMap absolute_phase_map(cv::Mat absolute, cv::Mat valid, const cv::Mat& uncertain,
                            const WrappedPhase& finest, double pitch_px, int projector_width) {
  settle_uncertain(absolute, valid, uncertain);
  correct_period_order(absolute, valid);
  clear_outside_projector(absolute, valid, pitch_px, projector_width);
  PhaseMap out;
  out.phase = absolute;
  out.quality = finest.modulation;
  out.texture = finest.mean;
  out.valid = valid;
  out.pitch_px = pitch_px;
  out.absolute = true;
  return out;
}

}  // namespace detail
}  // namespace gvkit::capture
