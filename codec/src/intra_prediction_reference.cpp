// Per-sample formulas of H.264 clauses 8.3.1.2, 8.3.2.2 (without reference sample filtering)
// and 8.3.3, plus the geometry modes. Slow and obvious on purpose.
#include <algorithm>

#include "gvkit/codec/intra_prediction.hpp"

namespace gvkit::codec {
namespace {

// p[x, y] with x = -1 the left column and y = -1 the top row.
int32_t p(const IntraNeighbors& nb, int x, int y) {
  if (y == -1) return x == -1 ? nb.corner : nb.top[x];
  return nb.left[y];
}

int32_t directional(int n, int mode, const IntraNeighbors& nb, int x, int y) {
  switch (mode) {
    case kIntraVertical:
      return p(nb, x, -1);
    case kIntraHorizontal:
      return p(nb, -1, y);
    case kIntraDiagonalDownLeft:
      if (x == n - 1 && y == n - 1)
        return (p(nb, 2 * n - 2, -1) + 3 * p(nb, 2 * n - 1, -1) + 2) >> 2;
      return (p(nb, x + y, -1) + 2 * p(nb, x + y + 1, -1) + p(nb, x + y + 2, -1) + 2) >> 2;
    case kIntraDiagonalDownRight:
      if (x > y)
        return (p(nb, x - y - 2, -1) + 2 * p(nb, x - y - 1, -1) + p(nb, x - y, -1) + 2) >> 2;
      if (x < y)
        return (p(nb, -1, y - x - 2) + 2 * p(nb, -1, y - x - 1) + p(nb, -1, y - x) + 2) >> 2;
      return (p(nb, 0, -1) + 2 * p(nb, -1, -1) + p(nb, -1, 0) + 2) >> 2;
    case kIntraVerticalRight: {
      const int z = 2 * x - y;
      if (z >= 0 && z % 2 == 0)
        return (p(nb, x - (y >> 1) - 1, -1) + p(nb, x - (y >> 1), -1) + 1) >> 1;
      if (z >= 0)
        return (p(nb, x - (y >> 1) - 2, -1) + 2 * p(nb, x - (y >> 1) - 1, -1) +
                p(nb, x - (y >> 1), -1) + 2) >>
               2;
      if (z == -1) return (p(nb, -1, 0) + 2 * p(nb, -1, -1) + p(nb, 0, -1) + 2) >> 2;
      return (p(nb, -1, y - 2 * x - 1) + 2 * p(nb, -1, y - 2 * x - 2) + p(nb, -1, y - 2 * x - 3) +
              2) >>
             2;
    }
    case kIntraHorizontalDown: {
      const int z = 2 * y - x;
      if (z >= 0 && z % 2 == 0)
        return (p(nb, -1, y - (x >> 1) - 1) + p(nb, -1, y - (x >> 1)) + 1) >> 1;
      if (z >= 0)
        return (p(nb, -1, y - (x >> 1) - 2) + 2 * p(nb, -1, y - (x >> 1) - 1) +
                p(nb, -1, y - (x >> 1)) + 2) >>
               2;
      if (z == -1) return (p(nb, -1, 0) + 2 * p(nb, -1, -1) + p(nb, 0, -1) + 2) >> 2;
      return (p(nb, x - 2 * y - 1, -1) + 2 * p(nb, x - 2 * y - 2, -1) + p(nb, x - 2 * y - 3, -1) +
              2) >>
             2;
    }
    case kIntraVerticalLeft:
      if (y % 2 == 0) return (p(nb, x + (y >> 1), -1) + p(nb, x + (y >> 1) + 1, -1) + 1) >> 1;
      return (p(nb, x + (y >> 1), -1) + 2 * p(nb, x + (y >> 1) + 1, -1) +
              p(nb, x + (y >> 1) + 2, -1) + 2) >>
             2;
    case kIntraHorizontalUp: {
      const int z = x + 2 * y;
      if (z < 2 * n - 3 && z % 2 == 0)
        return (p(nb, -1, y + (x >> 1)) + p(nb, -1, y + (x >> 1) + 1) + 1) >> 1;
      if (z < 2 * n - 3)
        return (p(nb, -1, y + (x >> 1)) + 2 * p(nb, -1, y + (x >> 1) + 1) +
                p(nb, -1, y + (x >> 1) + 2) + 2) >>
               2;
      if (z == 2 * n - 3) return (p(nb, -1, n - 2) + 3 * p(nb, -1, n - 1) + 2) >> 2;
      return p(nb, -1, n - 1);
    }
  }
  return 0;
}

int32_t dc(int n, const IntraNeighbors& nb) {
  int64_t sum = 0;
  for (int i = 0; i < n; ++i) sum += nb.top[i] + nb.left[i];
  int shift = 1;
  while ((1 << shift) < 2 * n) ++shift;
  return static_cast<int32_t>((sum + n) >> shift);
}

int32_t plane16(const IntraNeighbors& nb, int x, int y) {
  int64_t h = 0, v = 0;
  for (int i = 0; i < 8; ++i) {
    h += (i + 1) * (p(nb, 8 + i, -1) - p(nb, 6 - i, -1));
    v += (i + 1) * (p(nb, -1, 8 + i) - p(nb, -1, 6 - i));
  }
  const int64_t a = 16 * (static_cast<int64_t>(p(nb, -1, 15)) + p(nb, 15, -1));
  const int64_t b = (5 * h + 32) >> 6, c = (5 * v + 32) >> 6;
  return static_cast<int32_t>((a + b * (x - 7) + c * (y - 7) + 16) >> 5);
}

int32_t geometry(int mode, const IntraNeighbors& nb, int x, int y) {
  const int32_t c = nb.corner, t3 = nb.top[3], l3 = nb.left[3];
  switch (mode) {
    case kIntraGeoPlane:
      return nb.top[x] + nb.left[y] - c;
    case kIntraGeoVertical:
      return nb.top[x] + (((y + 1) * (l3 - c) + 2) >> 2);
    case kIntraGeoHorizontal:
      return nb.left[y] + (((x + 1) * (t3 - c) + 2) >> 2);
    default:
      return c + (((x + 1) * (t3 - c) + (y + 1) * (l3 - c) + 2) >> 2);
  }
}

}  // namespace

void predict_intra_reference(int n, int mode, const IntraNeighbors& nb, int max_value,
                             int32_t* out) {
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      int64_t v;
      if (n == 16 && mode == kIntra16x16Plane)
        v = plane16(nb, x, y);
      else if (mode == kIntraDc)
        v = dc(n, nb);
      else if (mode >= kIntraGeoPlane)
        v = geometry(mode, nb, x, y);
      else
        v = directional(n, mode, nb, x, y);
      out[y * n + x] = static_cast<int32_t>(std::clamp<int64_t>(v, 0, max_value));
    }
}

}  // namespace gvkit::codec
