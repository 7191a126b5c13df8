#pragma once
// Internal: constructors of the pattern families and helpers they share (pattern_set.cpp).

#include <memory>
#include <string>
#include <vector>

#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/phase_shift.hpp"

namespace gvkit::capture::detail {

std::unique_ptr<PatternSet> make_phase_shift(int steps, int periods, const PatternSetOptions& o);
std::unique_ptr<PatternSet> make_multi_frequency(int steps, std::vector<int> periods,
                                                 const PatternSetOptions& o);
std::unique_ptr<PatternSet> make_zhang_huang(int periods, const PatternSetOptions& o);
std::unique_ptr<PatternSet> make_gray_code(int bits, int steps, const PatternSetOptions& o);

// Ok when fringes has `count` images of one size and one 8/16-bit type; names the image.
Status check_fringes(const FringeSet& fringes, int count, const std::string& pattern_name);

// 0.5 * (1 + cos(2*pi*u/pitch - shift)) for every projector column u, CV_32F.
cv::Mat cosine_image(cv::Size size, double pitch_px, double shift_rad);

// Runs the fast or the reference phase-shift kernel per options.reference.
WrappedPhase decode_steps(const std::vector<cv::Mat>& images, int first, int steps,
                          const PatternSetOptions& options);

// valid = modulation >= min_modulation and not saturated (and finite phase).
cv::Mat valid_from(const WrappedPhase& w, const PatternSetOptions& options);

// Fills a PhaseMap from a spatially unwrapped single-frequency decode.
PhaseMap spatially_unwrapped(const WrappedPhase& w, double pitch_px, cv::Mat valid,
                             const PatternSetOptions& options);

}  // namespace gvkit::capture::detail
