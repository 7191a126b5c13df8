#pragma once
// Temporal coherence of a geometry video as in the seed's Fig. 8.6: the mean squared error per
// channel (X, Y, Z, mm^2) left after full-search block matching of each block of the current
// frame against the previous frame. Only pixels inside both frames' domain masks count.

#include <array>

#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

struct BlockMatchingOptions {
  int block_size = 16;    // px, H.264's macroblock
  int search_range = 16;  // px either way: a 32x32 full-search window
  Status check() const;
};

struct BlockMatchingError {
  std::array<double, 3> mse_mm2{};      // X, Y, Z
  double mean_mse_mm2 = 0;              // mean of the three
  double zero_motion_mean_mse_mm2 = 0;  // the same without motion search, for reference
  // mean_mse_mm2 with every pixel weighted by the surface area it samples in the current frame
  // (mm^2, from the cross product of its xyz differences to the next pixel across and down):
  // the error per unit of surface, which does not depend on how a layout spreads its pixels
  // over the face (a layout that gives more pixels to a moving region scores a higher plain MSE
  // for the same motion).
  double area_weighted_mean_mse_mm2 = 0;
};

// Fails when the images differ in size or type. Sums each candidate's squared differences with
// AVX2 where the processor has it; the figures are those of block_matching_error_reference (a
// candidate's sum may differ from the plain one in its last bits, so a choice between two
// candidates whose sums differ by that little may differ).
Result<BlockMatchingError> block_matching_error(const GeometryImage& reference,
                                                const GeometryImage& current,
                                                const BlockMatchingOptions& options = {});

// The plain C++ version of block_matching_error.
Result<BlockMatchingError> block_matching_error_reference(const GeometryImage& reference,
                                                          const GeometryImage& current,
                                                          const BlockMatchingOptions& options = {});

}  // namespace gvkit::facemap
