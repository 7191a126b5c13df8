#pragma once
// Cross-plane residual prediction (format 1.6, docs/bitstream.md 4.9): the Y and Z planes of a
// frame may add a scaled copy of the X plane's reconstructed residual to their own, per
// macroblock, with the scale alpha in {0, +-1, +-2, +-4, +-8} (eighths): the reconstructed
// residual of a Y or Z sample is its decoded residual plus (alpha * r_X) >> 3 (an arithmetic
// shift), r_X being X's residual at the same sample. This is H.265's cross-component
// prediction for 4:4:4 video applied to the x, y and z coordinates of a surface point.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "gvkit/codec/cross_plane_contexts.hpp"

namespace gvkit::codec {

struct MotionField;  // plane_coding.hpp

// The spatial-domain residual a coded plane added to its prediction, per sample (after the
// inverse transform; in transform-bypass planes the level times the near-lossless step), in
// sample units, row-major; and per macroblock (raster order) whether any of its samples is
// nonzero (a Y or Z macroblock codes a scale only then).
struct CrossPlaneResidual {
  int width = 0, height = 0;  // of the plane (multiples of 16)
  std::vector<int32_t> samples;
  std::vector<uint8_t> mb_nonzero;

  // Zero residual over a width x height plane (multiples of 16).
  void reset(int w, int h);
  int32_t at(int x, int y) const { return samples[static_cast<size_t>(y) * width + x]; }
  bool nonzero(int mb_x, int mb_y) const {
    return mb_nonzero[static_cast<size_t>(mb_y) * (width / 16) + mb_x] != 0;
  }
};

// The cross-plane links of one plane's coding: `source` (Y and Z planes) is the residual of the
// plane they predict from (X's), null when the tool is off; `residual_out` (the X plane) receives
// the plane's own residual. Either may be null.
struct CrossPlaneLinks {
  const CrossPlaneResidual* source = nullptr;
  CrossPlaneResidual* residual_out = nullptr;
  // Format 1.7, cross-plane contexts (cross_plane_contexts.hpp): `contexts` (Y and Z planes) are
  // the X plane's final context states, the plane's initial ones, null when the tool is off;
  // format 1.9, temporal contexts: the same plane's final states in the reference frame.
  // `contexts_out` receives the plane's final states. Either may be null.
  const CrossPlaneContextStates* contexts = nullptr;
  CrossPlaneContextStates* contexts_out = nullptr;
  // Format 1.11, merge (P planes): the same plane's motion in reference 0 (its co-located vector
  // is a merge candidate), null when that reference is not a P frame.
  const MotionField* reference_motion = nullptr;
};

// The allowed scales in increasing order, and the number of them.
inline constexpr int kCrossScaleCount = 9;
inline constexpr int kCrossScales[kCrossScaleCount] = {-8, -4, -2, -1, 0, 1, 2, 4, 8};
// Index of an allowed scale in kCrossScales (0..8); -1 if alpha is not one.
int cross_scale_index(int alpha);

// The term (alpha * r) >> 3 added to a sample's residual.
inline int32_t cross_plane_term(int alpha, int32_t r) {
  return static_cast<int32_t>((static_cast<int64_t>(alpha) * r) >> 3);
}

// Adds the cross-plane term of scale alpha to the n x n prediction block `pred` (row-major)
// at (x0, y0) of the plane; source is the residual predicted from. Nothing happens for alpha 0.
void add_cross_plane_term(int alpha, const CrossPlaneResidual& source, int x0, int y0, int n,
                          int32_t* pred);

// Encoder: the allowed scale nearest to the least-squares fit 8 sum(r r_X) / sum(r_X^2) of the
// 16x16 residual r (row-major) of the macroblock (mb_x, mb_y) against the source residual; 0
// when the source residual is zero there.
int least_squares_cross_scale(const int32_t* residual, const CrossPlaneResidual& source, int mb_x,
                              int mb_y);

}  // namespace gvkit::codec
