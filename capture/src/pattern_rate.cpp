// check_pattern_rate (pattern_projector.hpp): built without the projector window too, so that
// every capture path can refuse a pattern set the projector cannot show at the asked rate.
#include <cmath>
#include <cstdio>

#include "gvkit/capture/pattern_projector.hpp"

namespace gvkit {

Status check_pattern_rate(int n_patterns, double cycles_per_second, double refresh_hz) {
  if (n_patterns < 1) return invalid_argument("projector: the pattern set is empty");
  if (!(cycles_per_second > 0) || !std::isfinite(cycles_per_second))
    return invalid_argument("projector: the cycle rate must be > 0");
  if (!(refresh_hz > 0)) return Status::ok();  // unknown refresh: cannot tell
  const double asked = n_patterns * cycles_per_second;
  if (asked > refresh_hz * 1.001) {
    char text[256];
    std::snprintf(text, sizeof(text),
                  "projector: %d patterns at %.4g cycles/s need %.4g patterns/s, but the display "
                  "refreshes at %.4g Hz: at most %.4g cycles/s",
                  n_patterns, cycles_per_second, asked, refresh_hz, refresh_hz / n_patterns);
    return invalid_argument(text);
  }
  return Status::ok();
}

}  // namespace gvkit
