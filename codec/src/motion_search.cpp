#include "gvkit/codec/motion_search.hpp"

#include <algorithm>
#include <cstdlib>
#include <limits>

#include "gvkit/codec/block_distortion.hpp"

namespace gvkit::codec {
namespace {

// SAD of the source macroblock against the reference block at (x, y), edge-extended.
int64_t whole_sample_sad(const uint16_t* src, ptrdiff_t src_stride,
                         const InterpolatedReference& ref, int x, int y) {
  if (const uint16_t* r = ref.whole_block(x, y, 16, 16))
    return sad16x16(src, src_stride, r, ref.stride());
  const SamplePlane& p = ref.plane();
  int64_t sad = 0;
  for (int j = 0; j < 16; ++j) {
    const int sy = std::clamp(y + j, 0, p.height - 1);
    for (int i = 0; i < 16; ++i)
      sad += std::abs(static_cast<int>(src[j * src_stride + i]) -
                      p.at(std::clamp(x + i, 0, p.width - 1), sy));
  }
  return sad;
}

}  // namespace

double motion_vector_bits(int mx, int my, int px, int py, const MotionSearchParams& params) {
  if (params.has_shared && mx == params.shared_mv_x && my == params.shared_mv_y) return 1;
  return (params.has_shared ? 1 : 0) + signed_exp_golomb_bits(mx - px) +
         signed_exp_golomb_bits(my - py);
}

MotionSearchResult search_motion_16x16(const SamplePlane& src, const InterpolatedReference& ref,
                                       int x0, int y0, int px, int py,
                                       const MotionSearchParams& params) {
  const uint16_t* block = &src.samples[static_cast<size_t>(y0) * src.width + x0];
  const ptrdiff_t stride = src.width;
  const bool qpel = params.subpel != 0;
  const int unit = qpel ? 4 : 1;  // vector units per sample
  const double lambda = params.lambda;
  const int r = params.range;
  double best = std::numeric_limits<double>::infinity();
  int best_x = 0, best_y = 0;
  const auto joint_block = [&](const JointMotionPlane& j) {
    return &j.source->samples[static_cast<size_t>(y0) * j.source->width + x0];
  };
  const auto whole_cost = [&](int dx, int dy) {
    int64_t sad = whole_sample_sad(block, stride, ref, x0 + dx, y0 + dy);
    for (const JointMotionPlane& j : params.joint)
      sad += whole_sample_sad(joint_block(j), j.source->width, *j.reference, x0 + dx, y0 + dy);
    return static_cast<double>(sad) +
           lambda * motion_vector_bits(unit * dx, unit * dy, px, py, params);
  };
  if (params.pattern == MotionSearchPattern::kFull) {
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) {
        const double cost = whole_cost(dx, dy);
        if (cost < best) {
          best = cost;
          best_x = dx;
          best_y = dy;
        }
      }
  } else {
    // Each vector in range is measured at most once (bit per vector of the (2r+1)^2 window).
    const int side = 2 * r + 1;
    uint8_t seen[65 * 65];  // range <= 32
    GVKIT_CHECK(r >= 0 && r <= 32);
    std::fill(seen, seen + side * side, uint8_t{0});
    const auto visit = [&](int dx, int dy) {
      if (std::abs(dx) > r || std::abs(dy) > r) return false;
      uint8_t& s = seen[static_cast<size_t>(dy + r) * side + dx + r];
      if (s) return false;
      s = 1;
      const double cost = whole_cost(dx, dy);
      if (cost < best) {
        best = cost;
        best_x = dx;
        best_y = dy;
        return true;
      }
      return false;
    };
    // Seeds: zero and the predictor (rounded to whole samples, clamped to the range).
    visit(0, 0);
    const auto to_whole = [&](int v) {
      return std::clamp(v >= 0 ? (v + unit / 2) / unit : -((-v + unit / 2) / unit), -r, r);
    };
    visit(to_whole(px), to_whole(py));
    // Small diamond steps until the centre is the best, then its four diagonal neighbours.
    for (int step = 0; step < 4 * r + 4; ++step) {
      const int cx = best_x, cy = best_y;
      visit(cx - 1, cy);
      visit(cx + 1, cy);
      visit(cx, cy - 1);
      visit(cx, cy + 1);
      if (best_x == cx && best_y == cy) break;
    }
    const int cx = best_x, cy = best_y;
    for (int dy = -1; dy <= 1; dy += 2)
      for (int dx = -1; dx <= 1; dx += 2) visit(cx + dx, cy + dy);
  }
  MotionSearchResult result;
  result.whole_mv_x = result.mv_x = best_x * unit;
  result.whole_mv_y = result.mv_y = best_y * unit;
  if (!qpel) return result;
  best_x *= unit;
  best_y *= unit;
  int32_t pred[256];
  const auto distortion = [&](const uint16_t* b, ptrdiff_t s, const int32_t* p) {
    return params.lossless ? sad_block(16, b, s, p) : satd_block(16, b, s, p);
  };
  // A plane's distortion at (mx, my): SATD straight from the stored interpolated rows where
  // the block lies within their margin (the same value), else from the formed prediction.
  const auto plane_distortion = [&](const InterpolatedReference& r, const uint16_t* b, ptrdiff_t s,
                                    int mx, int my) {
    const uint16_t *first = nullptr, *second = nullptr;
    if (!params.lossless && r.quarter_block_rows(x0, y0, 16, 16, mx, my, &first, &second))
      return satd_block_of_average(16, b, s, first, second, r.stride());
    r.predict(x0, y0, 16, 16, mx, my, true, pred);
    return distortion(b, s, pred);
  };
  const auto cost_of = [&](int mx, int my) {
    int64_t d = plane_distortion(ref, block, stride, mx, my);
    for (const JointMotionPlane& j : params.joint)
      d += plane_distortion(*j.reference, joint_block(j), j.source->width, mx, my);
    return static_cast<double>(d) + lambda * motion_vector_bits(mx, my, px, py, params);
  };
  best = cost_of(best_x, best_y);
  const auto try_vector = [&](int mx, int my) {
    if (mx == best_x && my == best_y) return;
    const double c = cost_of(mx, my);
    if (c < best) {
      best = c;
      best_x = mx;
      best_y = my;
    }
  };
  try_vector(px, py);
  if (params.has_shared) try_vector(params.shared_mv_x, params.shared_mv_y);
  const int limit = params.max_abs_mv;
  for (int step = 2; step >= (params.subpel >= 4 ? 1 : 2); step /= 2) {
    const int cx = best_x, cy = best_y;
    for (int dy = -step; dy <= step; dy += step)
      for (int dx = -step; dx <= step; dx += step) {
        const int mx = cx + dx, my = cy + dy;
        if ((!dx && !dy) || std::abs(mx) > limit || std::abs(my) > limit) continue;
        const double c = cost_of(mx, my);
        if (c < best) {
          best = c;
          best_x = mx;
          best_y = my;
        }
      }
  }
  result.mv_x = best_x;
  result.mv_y = best_y;
  return result;
}

}  // namespace gvkit::codec
