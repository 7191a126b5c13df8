#include "gvkit/capture/pattern_set.hpp"

#include <cmath>
#include <limits>
#include <regex>

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
  const std::string where = "pattern set '" + name + "'";
  std::smatch m;
  auto bad = [&](const std::string& why) -> Status { return invalid_argument(where + ": " + why); };
  if (std::regex_match(name, m, std::regex(R"(psp(\d+)-f(\d+))"))) {
    const int steps = std::stoi(m[1]), periods = std::stoi(m[2]);
    if (steps < 3 || steps > 64) return bad("needs 3..64 steps");
    if (periods < 1 || periods > 4096) return bad("needs 1..4096 periods");
    return detail::make_phase_shift(steps, periods, options);
  }
  if (std::regex_match(name, m, std::regex(R"(mf(\d+)((-f\d+){2,3}))"))) {
    const int steps = std::stoi(m[1]);
    if (steps < 3 || steps > 64) return bad("needs 3..64 steps");
    std::vector<int> periods;
    const std::string list = m[2];
    std::regex f(R"(-f(\d+))");
    for (auto it = std::sregex_iterator(list.begin(), list.end(), f); it != std::sregex_iterator();
         ++it)
      periods.push_back(std::stoi((*it)[1]));
    if (periods.back() != 1) return bad("the last (coarsest) frequency must be f1");
    for (size_t i = 0; i + 1 < periods.size(); ++i)
      if (periods[i] <= periods[i + 1] || periods[i] > 4096)
        return bad("frequencies must decrease from finest to f1 (at most 4096 periods)");
    return detail::make_multi_frequency(steps, periods, options);
  }
  if (std::regex_match(name, m, std::regex(R"(zh-f(\d+))"))) {
    const int periods = std::stoi(m[1]);
    if (periods < 1 || periods > 4096) return bad("needs 1..4096 periods");
    return detail::make_zhang_huang(periods, options);
  }
  if (std::regex_match(name, m, std::regex(R"(gray(\d+)-psp(\d+))"))) {
    const int bits = std::stoi(m[1]), steps = std::stoi(m[2]);
    if (bits < 1 || bits > 12) return bad("needs 1..12 Gray-code bits");
    if (steps < 3 || steps > 64) return bad("needs 3..64 steps");
    return detail::make_gray_code(bits, steps, options);
  }
  return bad("unknown name; known: " + pattern_set_help());
}

std::string pattern_set_help() {
  return "psp<N>-f<P> (N-step phase shift, P periods, spatial unwrapping; e.g. psp3-f16), "
         "mf<N>-f<P1>-f<P2>[-f<P3>] (multi-frequency temporal unwrapping, finest first, last f1; "
         "e.g. mf3-f16-f1 = the 2x3 skull scheme, mf4-f16-f1, mf3-f64-f8-f1), "
         "zh-f<P> (Zhang-Huang 2+1; e.g. zh-f16), "
         "gray<B>-psp<N> (B Gray-code bits + N-step phase shift with 2^B periods; e.g. gray4-psp4)";
}

std::vector<std::string> pattern_set_candidates(int images) {
  std::vector<std::string> out;
  auto n = [](int v) { return std::to_string(v); };
  if (images >= 3 && images <= 64) out.push_back("psp" + n(images) + "-f<P>");
  if (images % 2 == 0 && images / 2 >= 3 && images / 2 <= 64)
    out.push_back("mf" + n(images / 2) + "-f<P>-f1");
  if (images % 3 == 0 && images / 3 >= 3 && images / 3 <= 64)
    out.push_back("mf" + n(images / 3) + "-f<P1>-f<P2>-f1");
  // Gray code + phase shift: the common splits (3 to 8 bits), most bits first.
  for (int bits = 8; bits >= 3; --bits)
    if (images - bits >= 3 && images - bits <= 64)
      out.push_back("gray" + n(bits) + "-psp" + n(images - bits));
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

}  // namespace detail
}  // namespace gvkit::capture
