#include "gvkit/codec/value_prediction.hpp"

#include <algorithm>
#include <cmath>

namespace gvkit::codec {
namespace {

uint64_t zigzag(int64_t v) { return (static_cast<uint64_t>(v) << 1) ^ (v < 0 ? ~uint64_t{0} : 0); }
int64_t unzigzag(uint64_t v) { return static_cast<int64_t>(v >> 1) ^ -static_cast<int64_t>(v & 1); }

int64_t to_fixed(double v, int64_t limit) {
  return std::clamp<int64_t>(std::llround(v * 65536.0), -limit, limit);
}

}  // namespace

bool ValueTransform::is_identity() const {
  for (int a = 0; a < 3; ++a) {
    if (t[a] != 0) return false;
    for (int b = 0; b < 3; ++b)
      if (m[a][b] != (a == b ? 65536 : 0)) return false;
  }
  return true;
}

ValueTransform fit_value_transform(const std::vector<SamplePlane>& current,
                                   const std::vector<SamplePlane>& reference, const cv::Mat& mask,
                                   ValuePrediction mode, int bit_depth) {
  GVKIT_CHECK(current.size() >= 3 && reference.size() >= 3);
  ValueTransform out;
  if (mode == ValuePrediction::kNone) return out;
  const double c = static_cast<double>(1 << (bit_depth - 1));
  // Normal equations of [ref_x - C, ref_y - C, ref_z - C, 1] -> cur_a - C, a = x, y, z.
  cv::Matx44d ata = cv::Matx44d::zeros();
  cv::Matx<double, 4, 3> atb = cv::Matx<double, 4, 3>::zeros();
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* m = mask.ptr<uint8_t>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (!m[x]) continue;
      const double r[4] = {reference[0].at(x, y) - c, reference[1].at(x, y) - c,
                           reference[2].at(x, y) - c, 1.0};
      const double s[3] = {current[0].at(x, y) - c, current[1].at(x, y) - c,
                           current[2].at(x, y) - c};
      for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) ata(i, j) += r[i] * r[j];
        for (int a = 0; a < 3; ++a) atb(i, a) += r[i] * s[a];
      }
    }
  }
  const double n = ata(3, 3);
  if (n < 16) return out;
  for (int a = 0; a < 3; ++a) {
    if (mode == ValuePrediction::kOffset) {
      // cur_a = ref_a + t: t is the mean difference.
      out.t[a] = to_fixed((atb(3, a) - ata(3, a)) / n, kMaxValueOffset);
      continue;
    }
    if (mode == ValuePrediction::kWeighted) {
      // cur_a = w ref_a + t on the centred samples.
      const cv::Matx22d A(ata(a, a), ata(a, 3), ata(3, a), n);
      const cv::Vec2d b(atb(a, a), atb(3, a));
      cv::Vec2d sol;
      if (!cv::solve(A, b, sol, cv::DECOMP_SVD)) continue;
      out.m[a][a] = to_fixed(sol[0], kMaxValueMatrix);
      out.t[a] = to_fixed(sol[1], kMaxValueOffset);
      continue;
    }
    cv::Vec4d b(atb(0, a), atb(1, a), atb(2, a), atb(3, a));
    cv::Vec4d sol;
    if (!cv::solve(ata, b, sol, cv::DECOMP_SVD)) continue;
    for (int k = 0; k < 3; ++k) out.m[a][k] = to_fixed(sol[k], kMaxValueMatrix);
    out.t[a] = to_fixed(sol[3], kMaxValueOffset);
  }
  return out;
}

std::vector<SamplePlane> apply_value_transform(const std::vector<SamplePlane>& reference,
                                               const ValueTransform& transform, int bit_depth) {
  GVKIT_CHECK(reference.size() >= 3);
  std::vector<SamplePlane> out = reference;
  const int64_t c = int64_t{1} << (bit_depth - 1), max_value = (int64_t{1} << bit_depth) - 1;
  const size_t count = reference[0].samples.size();
  for (size_t i = 0; i < count; ++i) {
    const int64_t r[3] = {reference[0].samples[i] - c, reference[1].samples[i] - c,
                          reference[2].samples[i] - c};
    for (int a = 0; a < 3; ++a) {
      const int64_t v = transform.m[a][0] * r[0] + transform.m[a][1] * r[1] +
                        transform.m[a][2] * r[2] + transform.t[a] + 32768;
      out[a].samples[i] = static_cast<uint16_t>(std::clamp<int64_t>((v >> 16) + c, 0, max_value));
    }
  }
  return out;
}

void write_value_transform(ByteWriter& w, const ValueTransform& transform) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) w.varint(zigzag(transform.m[a][b] - (a == b ? 65536 : 0)));
  for (int a = 0; a < 3; ++a) w.varint(zigzag(transform.t[a]));
}

Result<ValueTransform> read_value_transform(ByteReader& r) {
  ValueTransform out;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const int64_t d = unzigzag(r.varint());
      if (!r.ok()) return corrupt_data("value transform truncated");
      if (d < -2 * kMaxValueMatrix || d > 2 * kMaxValueMatrix)
        return corrupt_data("value transform matrix entry out of range");
      out.m[a][b] = d + (a == b ? 65536 : 0);
      if (std::abs(out.m[a][b]) > kMaxValueMatrix)
        return corrupt_data("value transform matrix entry out of range");
    }
  for (int a = 0; a < 3; ++a) {
    out.t[a] = unzigzag(r.varint());
    if (!r.ok()) return corrupt_data("value transform truncated");
    if (out.t[a] < -kMaxValueOffset || out.t[a] > kMaxValueOffset)
      return corrupt_data("value transform offset out of range");
  }
  return out;
}

}  // namespace gvkit::codec
