#pragma once
// Codec quality figures of DESIGN.md section 6, over domain pixels only: RMS and max point error
// (Euclidean distance in mm) and geometry PSNR = 20 log10(peak / RMS), peak = the bounding-box
// diagonal of the sequence.

#include <cstdint>

#include "gvkit/core/geometry_image.hpp"

namespace gvkit::codec {

struct GeometryError {
  double rms_mm = 0;
  double max_mm = 0;
  double sum_squared_mm2 = 0;  // for pooling several frames
  int64_t pixels = 0;          // domain pixels compared
  // PSNR (dB) for the given peak; +infinity when the error is zero.
  double psnr_db(double peak_mm) const;
};

// Compares reference and decoded xyz over reference.domain_mask (sizes must match: contract).
GeometryError geometry_error(const GeometryImage& reference, const GeometryImage& decoded);

// Accumulates frames: RMS over all pixels of all frames, max over all.
void accumulate(GeometryError& total, const GeometryError& frame);

}  // namespace gvkit::codec
