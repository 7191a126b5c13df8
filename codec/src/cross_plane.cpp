// Cross-plane residual prediction (docs/bitstream.md 4.9): the source plane's residual, the
// term added to a Y or Z prediction and the encoder's least-squares scale.
#include "gvkit/codec/cross_plane.hpp"

#include <algorithm>
#include <cmath>

#include "cross_plane_residual.hpp"
#include "gvkit/codec/inverse_residual.hpp"
#include "gvkit/codec/transform.hpp"
#include "gvkit/codec/transform16x16.hpp"

namespace gvkit::codec {

void CrossPlaneResidual::reset(int w, int h) {
  width = w;
  height = h;
  samples.assign(static_cast<size_t>(w) * h, 0);
  mb_nonzero.assign(static_cast<size_t>(w / 16) * (h / 16), 0);
}

int cross_scale_index(int alpha) {
  for (int i = 0; i < kCrossScaleCount; ++i)
    if (kCrossScales[i] == alpha) return i;
  return -1;
}

void add_cross_plane_term(int alpha, const CrossPlaneResidual& source, int x0, int y0, int n,
                          int32_t* pred) {
  if (alpha == 0) return;
  for (int y = 0; y < n; ++y) {
    const int32_t* r = &source.samples[static_cast<size_t>(y0 + y) * source.width + x0];
    for (int x = 0; x < n; ++x) pred[y * n + x] += cross_plane_term(alpha, r[x]);
  }
}

int least_squares_cross_scale(const int32_t* residual, const CrossPlaneResidual& source, int mb_x,
                              int mb_y) {
  double rr = 0, rx = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const double s = source.at(mb_x * 16 + x, mb_y * 16 + y);
      rr += s * s;
      rx += s * residual[y * 16 + x];
    }
  if (rr <= 0) return 0;
  const double fit = 8.0 * rx / rr;
  int best = 0;
  for (int a : kCrossScales)
    if (std::abs(fit - a) < std::abs(fit - best)) best = a;
  return best;
}

namespace detail {

void macroblock_residual(const MacroblockData& mb, const PlaneCodingParams& p, int32_t* out) {
  std::fill(out, out + 256, 0);
  if (mb.type == kMbInter && mb.skip) return;
  const auto block = [&](int n, const int32_t* levels, int x0, int y0) {
    const int count = n * n;
    if (!any_nonzero(levels, count)) return;
    int32_t r[256];
    if (p.lossless) {
      const int64_t step = 2 * static_cast<int64_t>(p.near_lossless) + 1;
      for (int i = 0; i < count; ++i) r[i] = static_cast<int32_t>(levels[i] * step);
    } else {
      inverse_residual(n, levels, p.qp_prime, r);
    }
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) out[(y0 + y) * 16 + x0 + x] = r[y * n + x];
  };
  // Only the blocks the cbp codes (the encoder may hold levels of a transform size it tried and
  // did not choose, e.g. when the chosen one quantized to cbp 0: the decoder reads none).
  const auto coded = [&](int quadrant) { return ((mb.cbp >> quadrant) & 1) != 0; };
  // I8x8, and inter / I16x16 macroblocks with the 8x8 transform of format 1.6 (4.8).
  if (mb.type == kMbI8x8 || ((mb.type == kMbInter || mb.type == kMbI16x16) && mb.transform == 8)) {
    for (int q = 0; q < 4; ++q)
      if (coded(q)) block(8, mb.levels8[q], (q & 1) * 8, (q >> 1) * 8);
    return;
  }
  if ((mb.type == kMbInter || mb.type == kMbI16x16) && mb.transform == 16) {  // 4.8: 16x16
    if (mb.cbp == 15) block(16, mb.levels16, 0, 0);
    return;
  }
  for (int b = 0; b < 16; ++b)
    if (coded(b >> 2)) block(4, mb.levels[b], block_x(b) * 4, block_y(b) * 4);
}

void record_macroblock_residual(CrossPlaneResidual& out, int mb_x, int mb_y,
                                const MacroblockData& mb, const PlaneCodingParams& p,
                                const CrossPlaneResidual* source) {
  int32_t r[256];
  macroblock_residual(mb, p, r);
  if (source && mb.cross_scale)
    add_cross_plane_term(mb.cross_scale, *source, mb_x * 16, mb_y * 16, 16, r);
  bool nonzero = false;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const int32_t v = r[y * 16 + x];
      out.samples[static_cast<size_t>(mb_y * 16 + y) * out.width + mb_x * 16 + x] = v;
      nonzero = nonzero || v != 0;
    }
  out.mb_nonzero[static_cast<size_t>(mb_y) * (out.width / 16) + mb_x] = nonzero;
}

}  // namespace detail
}  // namespace gvkit::codec
