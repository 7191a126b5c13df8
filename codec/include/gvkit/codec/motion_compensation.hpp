#pragma once
// Motion-compensated prediction from a reference plane with integer or quarter-sample motion
// vectors (docs/bitstream.md 4.4): H.264's luma interpolation (8.4.2.2.1) on B-bit samples, the
// 6-tap filter (1, -5, 20, 20, -5, 1) for half-sample positions and the rounded average of the
// two nearest integer / half samples for quarter positions. The reference is extended beyond its
// edges by repeating the edge samples (every tap's coordinates are clamped).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "gvkit/codec/plane_coding.hpp"

namespace gvkit::codec {

// The sample at quarter-sample position (xq / 4, yq / 4) of the edge-extended reference, in
// [0, 2^bit_depth - 1]. Any xq, yq (coordinates far outside clamp to the edge).
int32_t interpolate_quarter_sample(const SamplePlane& ref, int xq, int yq, int bit_depth);

// The motion-compensated sample for picture position (x, y): with quarter_pel the vector
// (mv_x, mv_y) is in quarter samples, else in whole samples.
inline int32_t motion_sample(const SamplePlane& ref, int x, int y, int mv_x, int mv_y,
                             bool quarter_pel, int bit_depth) {
  if (!quarter_pel) {
    const int sx = x + mv_x, sy = y + mv_y;
    return ref.at(sx < 0 ? 0 : (sx >= ref.width ? ref.width - 1 : sx),
                  sy < 0 ? 0 : (sy >= ref.height ? ref.height - 1 : sy));
  }
  return interpolate_quarter_sample(ref, 4 * x + mv_x, 4 * y + mv_y, bit_depth);
}

inline constexpr int kMaxMotionBlock = 16;

// Prediction of the w x h block at (x0, y0) (row-major into pred, w * h values), 1 <= w, h <=
// kMaxMotionBlock: all samples share one fractional phase, so the half-sample planes are
// computed once per block.
void predict_motion_block(const SamplePlane& ref, int x0, int y0, int w, int h, int mv_x, int mv_y,
                          bool quarter_pel, int bit_depth, int32_t* pred);
// The same, sample by sample through motion_sample (the plain reference implementation).
void predict_motion_block_reference(const SamplePlane& ref, int x0, int y0, int w, int h, int mv_x,
                                    int mv_y, bool quarter_pel, int bit_depth, int32_t* pred);

// A reference plane with its half-sample planes (H.264's b, h and j) precomputed once over the
// picture and a margin of `margin` samples around it (edge-extended), for an encoder that
// evaluates many vectors against one reference: a quarter-sample prediction is then the rounded
// average of two stored samples. Every value equals predict_motion_block's (and so
// interpolate_quarter_sample's); blocks reaching beyond the margin fall back to it.
class InterpolatedReference {
 public:
  // ref must outlive this object; 8 <= bit_depth <= 16, margin >= 0.
  InterpolatedReference(const SamplePlane& ref, int bit_depth, int margin);

  // As predict_motion_block(ref, x0, y0, w, h, mv_x, mv_y, quarter_pel, bit_depth, pred), for
  // any w, h > 0 (row-major into pred, w * h values).
  void predict(int x0, int y0, int w, int h, int mv_x, int mv_y, bool quarter_pel,
               int32_t* pred) const;
  // As motion_sample(ref, x, y, mv_x, mv_y, quarter_pel, bit_depth).
  int32_t sample(int x, int y, int mv_x, int mv_y, bool quarter_pel) const;
  // The whole-sample plane at (x, y), edge-extended, when the w x h block there lies within the
  // margin (else nullptr); rows are stride() samples apart.
  const uint16_t* whole_block(int x, int y, int w, int h) const;
  // The stored rows that predict()'s w x h block at (x0, y0) with quarter-sample vector
  // (mv_x, mv_y) is made of, when they lie within the margin (else false): *first alone
  // (*second null) or the rounded average (a + b + 1) >> 1 of *first and *second; rows are
  // stride() samples apart.
  bool quarter_block_rows(int x0, int y0, int w, int h, int mv_x, int mv_y, const uint16_t** first,
                          const uint16_t** second) const;
  ptrdiff_t stride() const { return stride_; }
  const SamplePlane& plane() const { return ref_; }
  int bit_depth() const { return bit_depth_; }

 private:
  // Index into the padded planes of picture position (x, y) (may be negative).
  ptrdiff_t index(int x, int y) const {
    return static_cast<ptrdiff_t>(y + margin_) * stride_ + x + margin_;
  }
  bool inside(int x, int y, int w, int h) const {
    return x >= -margin_ && y >= -margin_ && x + w <= ref_.width + margin_ &&
           y + h <= ref_.height + margin_;
  }

  const SamplePlane& ref_;
  int bit_depth_;
  int margin_;
  ptrdiff_t stride_;
  size_t plane_size_ = 0;
  // G (whole samples), b (half right), h (half below) and j, one after the other (one
  // allocation: freed and allocated again per plane, it stays in the heap, without page faults).
  std::vector<uint16_t> storage_;
};

}  // namespace gvkit::codec
