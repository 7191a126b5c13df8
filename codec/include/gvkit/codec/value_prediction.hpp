#pragma once
// Value-domain prediction of P frames: a per-frame affine map of the reference frame's (x, y, z)
// samples, applied before motion compensation. Geometry moves in value, not in the picture (the
// parameterization is fixed): a head that turns or shifts changes every xyz sample alike, which
// one 3x4 matrix per frame predicts. Fixed point (docs/bitstream.md 2.2), with C = 2^(B-1):
//   pred_a = clip(((sum_b m[a][b] (ref_b - C) + t[a] + 2^15) >> 16) + C, 0, 2^B - 1)
// m in units of 2^-16 (identity = 65536 on the diagonal), t in units of 2^-16 samples.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/codec/byte_io.hpp"
#include "gvkit/codec/encoder_options.hpp"
#include "gvkit/codec/plane_coding.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::codec {

struct ValueTransform {
  int64_t m[3][3] = {{65536, 0, 0}, {0, 65536, 0}, {0, 0, 65536}};
  int64_t t[3] = {0, 0, 0};
  bool is_identity() const;
};

inline constexpr int64_t kMaxValueMatrix = int64_t{1} << 20;  // |m| <= 16 (in 2^-16 units)
inline constexpr int64_t kMaxValueOffset = int64_t{1} << 40;  // |t| <= 2^24 samples

// Least-squares fit of current ~ transform(reference) over the pixels where mask != 0 (mask is
// width x height; the planes may be padded beyond it), restricted by mode (offset: identity
// matrix; weighted: diagonal; affine: full). planes[0..2] are X, Y, Z of equal size.
ValueTransform fit_value_transform(const std::vector<SamplePlane>& current,
                                   const std::vector<SamplePlane>& reference, const cv::Mat& mask,
                                   ValuePrediction mode, int bit_depth);

// The reference with X, Y, Z mapped by the transform (a texture plane is copied unchanged).
std::vector<SamplePlane> apply_value_transform(const std::vector<SamplePlane>& reference,
                                               const ValueTransform& transform, int bit_depth);

// Syntax: 12 signed (zig-zag) LEB128 varints: m - identity row by row, then t.
void write_value_transform(ByteWriter& w, const ValueTransform& transform);
// Fails when a value is missing or out of range.
Result<ValueTransform> read_value_transform(ByteReader& r);

}  // namespace gvkit::codec
