#include "gvkit/codec/transform16x16.hpp"

#include <algorithm>
#include <array>
#include <cstdlib>

#include "forward_transform16x16_simd.hpp"
#include "gvkit/codec/transform.hpp"

namespace gvkit::codec {
namespace {

constexpr int kForwardShift1 = 3, kForwardShift2 = 5;
constexpr int kInverseShift1 = 7, kInverseShift2 = 13;
// The step of qp' % 6 in 1/16 units (H.264's 4x4 DC scales: step = v / 16 x 2^(qp' / 6), which
// is quantizer_step) and its reciprocal: mf x v ~ 2^17.
constexpr int32_t kStep16[6] = {10, 11, 13, 14, 16, 18};
constexpr int32_t kMf16[6] = {13107, 11916, 10082, 9362, 8192, 7282};
// forward_transform16x16's output is 2^8 x orthonormal; level = c x mf / 2^(13 + 8 + qp' / 6).
constexpr int kQuantShift = 21;

int64_t round_shift(int64_t v, int shift) { return (v + (int64_t{1} << (shift - 1))) >> shift; }

int32_t clamp_output(int64_t v) {
  return static_cast<int32_t>(std::clamp<int64_t>(v, -(int64_t{1} << 30), int64_t{1} << 30));
}

// One 16-point pass: out[k * out_stride] = sum_n M[k][n] in[n * in_stride], shifted.
void forward_butterfly(const int64_t* in, int in_stride, int shift, int64_t* out, int out_stride) {
  const auto& m = kTransform16;
  int64_t e[8], o[8];
  for (int k = 0; k < 8; ++k) {
    e[k] = in[k * in_stride] + in[(15 - k) * in_stride];
    o[k] = in[k * in_stride] - in[(15 - k) * in_stride];
  }
  int64_t ee[4], eo[4];
  for (int k = 0; k < 4; ++k) {
    ee[k] = e[k] + e[7 - k];
    eo[k] = e[k] - e[7 - k];
  }
  const int64_t eee0 = ee[0] + ee[3], eeo0 = ee[0] - ee[3];
  const int64_t eee1 = ee[1] + ee[2], eeo1 = ee[1] - ee[2];
  out[0] = round_shift(64 * eee0 + 64 * eee1, shift);
  out[8 * out_stride] = round_shift(64 * eee0 - 64 * eee1, shift);
  out[4 * out_stride] = round_shift(83 * eeo0 + 36 * eeo1, shift);
  out[12 * out_stride] = round_shift(36 * eeo0 - 83 * eeo1, shift);
  for (int k = 2; k < 16; k += 4) {
    int64_t s = 0;
    for (int n = 0; n < 4; ++n) s += m[k][n] * eo[n];
    out[k * out_stride] = round_shift(s, shift);
  }
  for (int k = 1; k < 16; k += 2) {
    int64_t s = 0;
    for (int n = 0; n < 8; ++n) s += m[k][n] * o[n];
    out[k * out_stride] = round_shift(s, shift);
  }
}

// One inverse 16-point pass: out[n * out_stride] = sum_k M[k][n] in[k * in_stride], shifted.
void inverse_butterfly(const int64_t* in, int in_stride, int shift, int64_t* out, int out_stride) {
  const auto& m = kTransform16;
  int64_t o[8], eo[4];
  for (int n = 0; n < 8; ++n) {
    int64_t s = 0;
    for (int k = 1; k < 16; k += 2) s += m[k][n] * in[k * in_stride];
    o[n] = s;
  }
  for (int n = 0; n < 4; ++n) {
    int64_t s = 0;
    for (int k = 2; k < 16; k += 4) s += m[k][n] * in[k * in_stride];
    eo[n] = s;
  }
  const int64_t eeo0 = 83 * in[4 * in_stride] + 36 * in[12 * in_stride];
  const int64_t eeo1 = 36 * in[4 * in_stride] - 83 * in[12 * in_stride];
  const int64_t eee0 = 64 * in[0] + 64 * in[8 * in_stride];
  const int64_t eee1 = 64 * in[0] - 64 * in[8 * in_stride];
  const int64_t ee[4] = {eee0 + eeo0, eee1 + eeo1, eee1 - eeo1, eee0 - eeo0};
  int64_t e[8];
  for (int k = 0; k < 4; ++k) {
    e[k] = ee[k] + eo[k];
    e[k + 4] = ee[3 - k] - eo[3 - k];
  }
  for (int k = 0; k < 8; ++k) {
    out[k * out_stride] = round_shift(e[k] + o[k], shift);
    out[(k + 8) * out_stride] = round_shift(e[7 - k] - o[7 - k], shift);
  }
}

constexpr std::array<uint16_t, 256> make_zigzag16() {
  std::array<uint16_t, 256> scan{};
  int i = 0;
  for (int s = 0; s <= 30; ++s) {
    // Odd anti-diagonals run from the top right down to the left, even ones back up.
    for (int t = 0; t <= s; ++t) {
      const int x = s % 2 ? s - t : t, y = s - x;
      if (x < 16 && y < 16) scan[static_cast<size_t>(i++)] = static_cast<uint16_t>(y * 16 + x);
    }
  }
  return scan;
}

}  // namespace

const int8_t kTransform16[16][16] = {
    {64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64, 64},
    {90, 87, 80, 70, 57, 43, 25, 9, -9, -25, -43, -57, -70, -80, -87, -90},
    {89, 75, 50, 18, -18, -50, -75, -89, -89, -75, -50, -18, 18, 50, 75, 89},
    {87, 57, 9, -43, -80, -90, -70, -25, 25, 70, 90, 80, 43, -9, -57, -87},
    {83, 36, -36, -83, -83, -36, 36, 83, 83, 36, -36, -83, -83, -36, 36, 83},
    {80, 9, -70, -87, -25, 57, 90, 43, -43, -90, -57, 25, 87, 70, -9, -80},
    {75, -18, -89, -50, 50, 89, 18, -75, -75, 18, 89, 50, -50, -89, -18, 75},
    {70, -43, -87, 9, 90, 25, -80, -57, 57, 80, -25, -90, -9, 87, 43, -70},
    {64, -64, -64, 64, 64, -64, -64, 64, 64, -64, -64, 64, 64, -64, -64, 64},
    {57, -80, -25, 90, -9, -87, 43, 70, -70, -43, 87, 9, -90, 25, 80, -57},
    {50, -89, 18, 75, -75, -18, 89, -50, -50, 89, -18, -75, 75, 18, -89, 50},
    {43, -90, 57, 25, -87, 70, 9, -80, 80, -9, -70, 87, -25, -57, 90, -43},
    {36, -83, 83, -36, -36, 83, -83, 36, 36, -83, 83, -36, -36, 83, -83, 36},
    {25, -70, 90, -80, 43, 9, -57, 87, -87, 57, -9, -43, 80, -90, 70, -25},
    {18, -50, 75, -89, 89, -75, 50, -18, -18, 50, -75, 89, -89, 75, -50, 18},
    {9, -25, 43, -57, 70, -80, 87, -90, 90, -87, 80, -70, 57, -43, 25, -9}};

const std::array<uint16_t, 256> kZigzag16x16 = make_zigzag16();

void forward_transform16x16(const int32_t* residual, int32_t* coeffs) {
  // Residuals below 2^14 (nearly all): the 32-bit vectorised version, the same output.
  if (detail::forward_transform16x16_fits_32(residual))
    detail::forward_transform16x16_32_avx2(residual, coeffs);
  else
    forward_transform16x16_butterfly64(residual, coeffs);
}

void forward_transform16x16_butterfly64(const int32_t* residual, int32_t* coeffs) {
  int64_t in[256], t[256], out[256];
  for (int i = 0; i < 256; ++i) in[i] = residual[i];
  // Rows (over x), then columns (over y).
  for (int y = 0; y < 16; ++y) forward_butterfly(in + 16 * y, 1, kForwardShift1, t + 16 * y, 1);
  for (int x = 0; x < 16; ++x) forward_butterfly(t + x, 16, kForwardShift2, out + x, 16);
  for (int i = 0; i < 256; ++i) coeffs[i] = static_cast<int32_t>(out[i]);
}

void inverse_transform16x16(const int64_t* coeffs, int32_t* residual) {
  int64_t t[256], out[256];
  // Columns first (over the vertical frequency), then rows.
  for (int x = 0; x < 16; ++x) inverse_butterfly(coeffs + x, 16, kInverseShift1, t + x, 16);
  for (int y = 0; y < 16; ++y) inverse_butterfly(t + 16 * y, 1, kInverseShift2, out + 16 * y, 1);
  for (int i = 0; i < 256; ++i) residual[i] = clamp_output(out[i]);
}

void forward_transform(int n, const int32_t* residual, int32_t* coeffs) {
  if (n == 4)
    forward_transform4x4(residual, coeffs);
  else if (n == 8)
    forward_transform8x8(residual, coeffs);
  else
    forward_transform16x16(residual, coeffs);
}

void forward_transform16x16_reference(const int32_t* r, int32_t* c) {
  int64_t t[256];
  for (int y = 0; y < 16; ++y)
    for (int k = 0; k < 16; ++k) {
      int64_t s = 0;
      for (int x = 0; x < 16; ++x) s += int64_t{kTransform16[k][x]} * r[y * 16 + x];
      t[y * 16 + k] = round_shift(s, kForwardShift1);
    }
  for (int l = 0; l < 16; ++l)
    for (int k = 0; k < 16; ++k) {
      int64_t s = 0;
      for (int y = 0; y < 16; ++y) s += int64_t{kTransform16[l][y]} * t[y * 16 + k];
      c[l * 16 + k] = static_cast<int32_t>(round_shift(s, kForwardShift2));
    }
}

void inverse_transform16x16_reference(const int64_t* c, int32_t* r) {
  int64_t t[256];
  for (int y = 0; y < 16; ++y)
    for (int k = 0; k < 16; ++k) {
      int64_t s = 0;
      for (int l = 0; l < 16; ++l) s += int64_t{kTransform16[l][y]} * c[l * 16 + k];
      t[y * 16 + k] = round_shift(s, kInverseShift1);
    }
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      int64_t s = 0;
      for (int k = 0; k < 16; ++k) s += int64_t{kTransform16[k][x]} * t[y * 16 + k];
      r[y * 16 + x] = clamp_output(round_shift(s, kInverseShift2));
    }
}

void quantize16x16(const int32_t* coeffs, int qp, bool inter_dead_zone, int32_t* levels) {
  const int qbits = kQuantShift + qp / 6;
  const int64_t mf = kMf16[qp % 6];
  const int64_t f = (int64_t{1} << qbits) / (inter_dead_zone ? 6 : 3);
  for (int k = 0; k < 256; ++k) {
    const int64_t w = coeffs[k];
    const int64_t z = (std::llabs(w) * mf + f) >> qbits;
    levels[k] = static_cast<int32_t>(w < 0 ? -z : z);
  }
}

int quantization_numerators16x16(const int32_t* coeffs, int qp, int64_t* numer) {
  absolute_products(coeffs, kMf16[qp % 6], 256, numer);
  return kQuantShift + qp / 6;
}

int64_t dequantization_scale16x16(int qp) { return int64_t{kStep16[qp % 6]} << (qp / 6); }

void dequantize16x16(const int32_t* levels, int qp, int64_t* coeffs) {
  const int64_t scale = dequantization_scale16x16(qp);
  for (int k = 0; k < 256; ++k) coeffs[k] = levels[k] * scale;
}

}  // namespace gvkit::codec
