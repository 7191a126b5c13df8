// Block-at-a-time predictors. The six diagonal modes of 4x4 and 8x8 blocks read every sample
// from one of three arrays over the neighbours laid out in a line (left column bottom-up,
// corner, top row): the samples themselves, the 3-tap filter (1, 2, 1) and the 2-tap mean at
// each position; which array and position for each (mode, x, y) is tabulated once from the
// index arithmetic of H.264's formulas (clause 8.3.1.2).
#include "gvkit/codec/intra_prediction.hpp"

#include <algorithm>
#include <cstddef>

namespace gvkit::codec {
namespace {

inline int32_t clip(int64_t v, int max_value) {
  return static_cast<int32_t>(v < 0 ? 0 : (v > max_value ? max_value : v));
}

// Layout of the neighbour line of an N x N block: index 1 + k holds e[k] with e[N - 1 - y] =
// left[y], e[N] = corner, e[N + 1 + x] = top[x] (x < 2N); e[-1] repeats left[N - 1] and
// e[3N + 1] repeats top[2N - 1], which gives the standard's special end values as plain filters.
enum LineKind : uint8_t { kRaw = 0, kFilter3 = 1, kMean2 = 2 };
constexpr int kLineSize = 3 * 8 + 3;

// Entry of a directional sample: kind * kLineSize + (1 + k).
template <int N>
uint8_t line_entry(int mode, int x, int y) {
  const auto entry = [](LineKind kind, int k) {
    return static_cast<uint8_t>(kind * kLineSize + 1 + k);
  };
  switch (mode) {
    case kIntraDiagonalDownLeft:
      return entry(kFilter3, N + 2 + x + y);
    case kIntraDiagonalDownRight:
      return entry(kFilter3, N + x - y);
    case kIntraVerticalRight: {
      const int z = 2 * x - y;
      if (z >= 0) return entry(z % 2 == 0 ? kMean2 : kFilter3, N + x - (y >> 1));
      if (z == -1) return entry(kFilter3, N);
      return entry(kFilter3, N + 1 + 2 * x - y);
    }
    case kIntraHorizontalDown: {
      const int z = 2 * y - x;
      if (z >= 0 && z % 2 == 0) return entry(kMean2, N - 1 - y + (x >> 1));
      if (z >= 0) return entry(kFilter3, N - y + (x >> 1));
      if (z == -1) return entry(kFilter3, N);
      return entry(kFilter3, N - 1 + x - 2 * y);
    }
    case kIntraVerticalLeft:
      return y % 2 == 0 ? entry(kMean2, N + 1 + x + (y >> 1))
                        : entry(kFilter3, N + 2 + x + (y >> 1));
    default: {  // horizontal up
      const int z = x + 2 * y;
      if (z < 2 * N - 3 && z % 2 == 0) return entry(kMean2, N - 2 - y - (x >> 1));
      if (z < 2 * N - 3) return entry(kFilter3, N - 2 - y - (x >> 1));
      if (z == 2 * N - 3) return entry(kFilter3, 0);
      return entry(kRaw, 0);
    }
  }
}

template <int N>
struct DirectionalTables {
  uint8_t entry[kIntraHorizontalUp + 1][N * N];
  DirectionalTables() {
    for (int mode = kIntraDiagonalDownLeft; mode <= kIntraHorizontalUp; ++mode)
      for (int y = 0; y < N; ++y)
        for (int x = 0; x < N; ++x) entry[mode][y * N + x] = line_entry<N>(mode, x, y);
  }
};

// The three arrays over the neighbour line of an N x N block (raw, 3-tap, 2-tap).
template <int N>
void make_line(const IntraNeighbors& nb, int32_t* line) {
  int32_t* e = line + 1;  // e[k], k = -1 .. 3N + 1
  for (int y = 0; y < N; ++y) e[N - 1 - y] = nb.left[y];
  e[N] = nb.corner;
  for (int x = 0; x < 2 * N; ++x) e[N + 1 + x] = nb.top[x];
  e[-1] = nb.left[N - 1];
  e[3 * N + 1] = nb.top[2 * N - 1];
  for (int k = 0; k <= 3 * N; ++k) {
    line[kFilter3 * kLineSize + 1 + k] = (e[k - 1] + 2 * e[k] + e[k + 1] + 2) >> 2;
    line[kMean2 * kLineSize + 1 + k] = (e[k] + e[k + 1] + 1) >> 1;
  }
}

template <int N>
void predict_directional(int mode, const int32_t* line, int32_t* out) {
  static const DirectionalTables<N> tables;
  const uint8_t* entry = tables.entry[mode];
  for (int i = 0; i < N * N; ++i) out[i] = line[entry[i]];
}

template <int N>
void predict_directional(int mode, const IntraNeighbors& nb, int32_t* out) {
  int32_t line[3 * kLineSize];
  make_line<N>(nb, line);
  predict_directional<N>(mode, line, out);
}

template <int N>
void predict_block(int mode, const IntraNeighbors& nb, int max_value, int32_t* out) {
  switch (mode) {
    case kIntraVertical:
      for (int y = 0; y < N; ++y) std::copy(nb.top, nb.top + N, out + y * N);
      return;
    case kIntraHorizontal:
      for (int y = 0; y < N; ++y) std::fill(out + y * N, out + (y + 1) * N, nb.left[y]);
      return;
    case kIntraDc: {
      int64_t sum = N;
      for (int i = 0; i < N; ++i) sum += nb.top[i] + nb.left[i];
      const int shift = N == 4 ? 3 : (N == 8 ? 4 : 5);
      std::fill(out, out + N * N, static_cast<int32_t>(sum >> shift));
      return;
    }
    default:
      break;
  }
  if (N == 16 && mode == kIntra16x16Plane) {
    int64_t h = 0, v = 0;
    for (int i = 0; i < 8; ++i) {
      const int32_t top_minus = i == 7 ? nb.corner : nb.top[6 - i];
      const int32_t left_minus = i == 7 ? nb.corner : nb.left[6 - i];
      h += (i + 1) * (nb.top[8 + i] - top_minus);
      v += (i + 1) * (nb.left[8 + i] - left_minus);
    }
    const int64_t a = 16 * (static_cast<int64_t>(nb.left[15]) + nb.top[15]);
    const int64_t b = (5 * h + 32) >> 6, c = (5 * v + 32) >> 6;
    int64_t row = a - 7 * b - 7 * c + 16;
    for (int y = 0; y < N; ++y, row += c) {
      int64_t acc = row;
      for (int x = 0; x < N; ++x, acc += b) out[y * N + x] = clip(acc >> 5, max_value);
    }
    return;
  }
  if (N == 4 && mode >= kIntraGeoPlane) {
    // |values| < 2^19: 32-bit arithmetic is exact. One loop per mode (no switch per sample).
    const int32_t c = nb.corner, dt = nb.top[3] - c, dl = nb.left[3] - c;
    const auto clip32 = [max_value](int32_t v) {
      return v < 0 ? 0 : (v > max_value ? max_value : v);
    };
    switch (mode) {
      case kIntraGeoPlane:
        for (int y = 0; y < 4; ++y)
          for (int x = 0; x < 4; ++x) out[y * 4 + x] = clip32(nb.top[x] + nb.left[y] - c);
        return;
      case kIntraGeoVertical:
        for (int y = 0; y < 4; ++y) {
          const int32_t d = ((y + 1) * dl + 2) >> 2;
          for (int x = 0; x < 4; ++x) out[y * 4 + x] = clip32(nb.top[x] + d);
        }
        return;
      case kIntraGeoHorizontal:
        for (int x = 0; x < 4; ++x) {
          const int32_t d = ((x + 1) * dt + 2) >> 2;
          for (int y = 0; y < 4; ++y) out[y * 4 + x] = clip32(nb.left[y] + d);
        }
        return;
      default:
        for (int y = 0; y < 4; ++y)
          for (int x = 0; x < 4; ++x)
            out[y * 4 + x] = clip32(c + (((x + 1) * dt + (y + 1) * dl + 2) >> 2));
        return;
    }
  }
  if (N <= 8 && mode >= kIntraDiagonalDownLeft && mode <= kIntraHorizontalUp)
    return predict_directional < N <= 8 ? N : 8 > (mode, nb, out);
  predict_intra_reference(N, mode, nb, max_value, out);
}

}  // namespace

void predict_intra(int n, int mode, const IntraNeighbors& nb, int max_value, int32_t* out) {
  switch (n) {
    case 4:
      return predict_block<4>(mode, nb, max_value, out);
    case 8:
      return predict_block<8>(mode, nb, max_value, out);
    default:
      return predict_block<16>(mode, nb, max_value, out);
  }
}

void predict_intra4x4_modes(const IntraNeighbors& nb, int max_value, int mode_count,
                            int32_t (*out)[16]) {
  int32_t line[3 * kLineSize];
  make_line<4>(nb, line);
  for (int mode = 0; mode < mode_count; ++mode) {
    if (mode >= kIntraDiagonalDownLeft && mode <= kIntraHorizontalUp)
      predict_directional<4>(mode, line, out[mode]);
    else
      predict_block<4>(mode, nb, max_value, out[mode]);
  }
}

IntraNeighbors make_neighbors(const uint16_t* plane, int stride, int x0, int y0, int n,
                              bool top_available, bool left_available, bool top_right_available,
                              int bit_depth) {
  IntraNeighbors nb;
  if (top_available) {
    const uint16_t* row = plane + static_cast<ptrdiff_t>(y0 - 1) * stride + x0;
    for (int i = 0; i < n; ++i) nb.top[i] = row[i];
    for (int i = n; i < 2 * n; ++i) nb.top[i] = top_right_available ? row[i] : row[n - 1];
  }
  if (left_available)
    for (int i = 0; i < n; ++i)
      nb.left[i] = plane[static_cast<ptrdiff_t>(y0 + i) * stride + x0 - 1];
  if (top_available && left_available) {
    nb.corner = plane[static_cast<ptrdiff_t>(y0 - 1) * stride + x0 - 1];
  } else if (top_available) {
    nb.corner = nb.top[0];
    std::fill(nb.left, nb.left + n, nb.top[0]);
  } else if (left_available) {
    nb.corner = nb.left[0];
    std::fill(nb.top, nb.top + 2 * n, nb.left[0]);
  } else {
    const int32_t mid = 1 << (bit_depth - 1);
    nb.corner = mid;
    std::fill(nb.top, nb.top + 2 * n, mid);
    std::fill(nb.left, nb.left + n, mid);
  }
  return nb;
}

}  // namespace gvkit::codec
