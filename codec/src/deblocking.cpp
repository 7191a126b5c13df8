#include "gvkit/codec/deblocking.hpp"

#include <algorithm>
#include <cstdlib>

namespace gvkit::codec {
namespace {

// One line across an edge: s points at q0, p_i = s[-(i + 1) step], q_i = s[i step].
inline void filter_line(uint16_t* s, ptrdiff_t step, int64_t beta, int64_t tc, int max_value) {
  const int64_t p0 = s[-step], p1 = s[-2 * step], p2 = s[-3 * step];
  const int64_t q0 = s[0], q1 = s[step], q2 = s[2 * step];
  const int64_t dp = std::abs(p2 - 2 * p1 + p0), dq = std::abs(q2 - 2 * q1 + q0);
  if (dp + dq >= beta) return;
  int64_t delta = (9 * (q0 - p0) - 3 * (q1 - p1) + 8) >> 4;
  if (std::abs(delta) >= 10 * tc) return;  // a real edge of the surface, not blocking
  delta = std::clamp(delta, -tc, tc);
  const auto clip = [max_value](int64_t v) {
    return static_cast<uint16_t>(std::clamp<int64_t>(v, 0, max_value));
  };
  s[-step] = clip(p0 + delta);
  s[0] = clip(q0 - delta);
  const int64_t side = (beta + (beta >> 1)) >> 3, half = tc >> 1;
  if (dp < side)
    s[-2 * step] = clip(p1 + std::clamp((((p2 + p0 + 1) >> 1) - p1 + delta) >> 1, -half, half));
  if (dq < side)
    s[step] = clip(q1 + std::clamp((((q2 + q0 + 1) >> 1) - q1 - delta) >> 1, -half, half));
}

}  // namespace

int64_t deblocking_step16(int qp_prime) {
  static constexpr int64_t kStep16[6] = {10, 11, 13, 14, 16, 18};
  GVKIT_CHECK(qp_prime >= 0 && qp_prime <= 99);
  return kStep16[qp_prime % 6] << (qp_prime / 6);
}

void deblock_plane(SamplePlane& plane, const DeblockingStrengths& strengths, int qp_prime,
                   int bit_depth, const DeblockingParams& params) {
  GVKIT_CHECK(plane.width % 8 == 0 && plane.height % 8 == 0 &&
              strengths.blocks_x == plane.width / 4 && strengths.blocks_y == plane.height / 4 &&
              strengths.vertical.size() ==
                  static_cast<size_t>(strengths.blocks_x) * strengths.blocks_y &&
              strengths.horizontal.size() == strengths.vertical.size());
  const int64_t step16 = deblocking_step16(qp_prime);
  const int64_t beta = params.beta * step16 / 64, tc1 = params.tc * step16 / 256;
  if (beta <= 0 || tc1 <= 0) return;
  const int max_value = (1 << bit_depth) - 1;
  const int bx = strengths.blocks_x, by = strengths.blocks_y;
  const ptrdiff_t stride = plane.width;
  for (int gy = 0; gy < by; ++gy)
    for (int gx = 2; gx < bx; gx += 2) {
      const int bs = strengths.vertical[static_cast<size_t>(gy) * bx + gx];
      if (bs == 0) continue;
      uint16_t* s = &plane.samples[static_cast<size_t>(gy) * 4 * stride + gx * 4];
      for (int k = 0; k < 4; ++k) filter_line(s + k * stride, 1, beta, bs * tc1, max_value);
    }
  for (int gy = 2; gy < by; gy += 2)
    for (int gx = 0; gx < bx; ++gx) {
      const int bs = strengths.horizontal[static_cast<size_t>(gy) * bx + gx];
      if (bs == 0) continue;
      uint16_t* s = &plane.samples[static_cast<size_t>(gy) * 4 * stride + gx * 4];
      for (int k = 0; k < 4; ++k) filter_line(s + k, stride, beta, bs * tc1, max_value);
    }
}

}  // namespace gvkit::codec
