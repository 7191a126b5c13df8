#include "gvkit/codec/partition_search.hpp"

#include <algorithm>
#include <cstdlib>
#include <limits>

#include "gvkit/codec/block_distortion.hpp"
#include "gvkit/codec/motion_search.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::codec {

BlockDistortionMemo::BlockDistortionMemo() : slots_(kSlots) {}

uint64_t BlockDistortionMemo::key_of(int ref, int x0, int y0, int mx, int my) {
  // 8 + 14 + 14 bits of reference and 8x8 block position (in 8-sample units, below 2^14), 14 + 14
  // of vector components (|v| < 2^13 vector units): unique for every argument the search gives.
  return (uint64_t(uint8_t(ref)) << 56) | (uint64_t(uint32_t(x0 / 8) & 0x3fffu) << 42) |
         (uint64_t(uint32_t(y0 / 8) & 0x3fffu) << 28) | (uint64_t(uint32_t(mx) & 0x3fffu) << 14) |
         uint64_t(uint32_t(my) & 0x3fffu);
}

// Linear probing without removals: store() fills the first free slot of a key's chain, so a key
// not found before a free slot is not stored.
int64_t BlockDistortionMemo::find(int ref, int x0, int y0, int mx, int my) const {
  const uint64_t key = key_of(ref, x0, y0, mx, my);
  for (size_t i = (key * 0x9E3779B97F4A7C15ull) >> 54, n = 0; n < 8;
       ++n, i = (i + 1) & (kSlots - 1)) {
    if (slots_[i].generation != generation_) return -1;
    if (slots_[i].key == key) return slots_[i].value;
  }
  return -1;
}

void BlockDistortionMemo::store(int ref, int x0, int y0, int mx, int my, int64_t distortion) {
  const uint64_t key = key_of(ref, x0, y0, mx, my);
  for (size_t i = (key * 0x9E3779B97F4A7C15ull) >> 54, n = 0; n < 8;
       ++n, i = (i + 1) & (kSlots - 1))
    if (slots_[i].generation != generation_) {
      slots_[i] = {key, generation_, distortion};
      return;
    }
}

PartitionVector search_partition_motion(const SamplePlane& src, const InterpolatedReference& ref,
                                        int x0, int y0, int w, int h, int px, int py,
                                        std::span<const int> starts,
                                        const PartitionSearchParams& params,
                                        BlockDistortionMemo* memo, int ref_id) {
  GVKIT_CHECK((w == 8 || w == 16) && (h == 8 || h == 16) && starts.size() >= 2 &&
              starts.size() % 2 == 0);
  const bool qpel = params.subpel != 0;
  const int unit = qpel ? 4 : 1;
  const int limit = params.max_abs_mv;
  const auto cost_of = [&](int mx, int my) {
    int64_t d = 0;
    int32_t pred[64];
    for (int by = 0; by < h; by += 8)
      for (int bx = 0; bx < w; bx += 8) {
        const int64_t known = memo ? memo->find(ref_id, x0 + bx, y0 + by, mx, my) : -1;
        if (known >= 0) {
          d += known;
          continue;
        }
        const uint16_t* s = &src.samples[static_cast<size_t>(y0 + by) * src.width + x0 + bx];
        // SATD straight from the stored interpolated rows where they hold the block.
        const uint16_t *first = nullptr, *second = nullptr;
        int64_t block = 0;
        if (qpel && !params.lossless &&
            ref.quarter_block_rows(x0 + bx, y0 + by, 8, 8, mx, my, &first, &second)) {
          block = satd_block_of_average(8, s, src.width, first, second, ref.stride());
        } else {
          ref.predict(x0 + bx, y0 + by, 8, 8, mx, my, qpel, pred);
          block = params.lossless ? sad_block(8, s, src.width, pred)
                                  : satd_block(8, s, src.width, pred);
        }
        if (memo) memo->store(ref_id, x0 + bx, y0 + by, mx, my, block);
        d += block;
      }
    return static_cast<double>(d) +
           params.lambda * (signed_exp_golomb_bits(mx - px) + signed_exp_golomb_bits(my - py));
  };
  PartitionVector best;
  best.cost = std::numeric_limits<double>::infinity();
  const auto visit = [&](int mx, int my) {
    if (std::abs(mx) > limit || std::abs(my) > limit) return false;
    const double c = cost_of(mx, my);
    if (c < best.cost) {
      best = {mx, my, c};
      return true;
    }
    return false;
  };
  for (size_t i = 0; i + 1 < starts.size(); i += 2) {
    bool seen = false;
    for (size_t j = 0; j < i; j += 2)
      seen |= starts[j] == starts[i] && starts[j + 1] == starts[i + 1];
    if (!seen) visit(starts[i], starts[i + 1]);
  }
  if (!(best.cost < std::numeric_limits<double>::infinity())) {
    // Every start beyond the limit: the predictor clamped into it.
    visit(std::clamp(px, -limit, limit), std::clamp(py, -limit, limit));
  }
  // Whole-sample diamond steps from the best start.
  int from_x = best.mv_x + 1, from_y = best.mv_y;  // not the centre: the first step runs
  for (int step = 0; step < params.max_steps && (best.mv_x != from_x || best.mv_y != from_y);
       ++step) {
    const int cx = best.mv_x, cy = best.mv_y;
    from_x = cx;
    from_y = cy;
    visit(cx - unit, cy);
    visit(cx + unit, cy);
    visit(cx, cy - unit);
    visit(cx, cy + unit);
  }
  if (!qpel) return best;
  for (int step = 2; step >= (params.subpel >= 4 ? 1 : 2); step /= 2) {
    const int cx = best.mv_x, cy = best.mv_y;
    for (int dy = -step; dy <= step; dy += step)
      for (int dx = -step; dx <= step; dx += step)
        if (dx || dy) visit(cx + dx, cy + dy);
  }
  return best;
}

}  // namespace gvkit::codec
