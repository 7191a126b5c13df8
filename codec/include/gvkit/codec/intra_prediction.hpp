#pragma once
// Intra prediction of one block from its reconstructed neighbours: H.264's nine 4x4 and 8x8
// modes and four 16x16 modes, plus four geometry (gradient-continuation) 4x4 modes after the
// seed's section 8.2. Samples are integers in [0, max_value]. Neighbours that lie outside the
// picture are substituted before prediction (see make_neighbors), so every mode is always usable.
//
// Geometry modes (T = top row, L = left column, C = corner, x, y in 0..3, >> is a floor shift):
//   kGeoPlane   (9)  T[x] + L[y] - C            the seed's modes 1 and 3 (see docs/bitstream.md)
//   kGeoVertical(10) T[x] + (((y+1)(L[3]-C) + 2) >> 2)   the seed's mode 2
//   kGeoHorizontal(11) L[y] + (((x+1)(T[3]-C) + 2) >> 2) the seed's mode 4
//   kGeoMeanPlane(12) C + (((x+1)(T[3]-C) + (y+1)(L[3]-C) + 2) >> 2)
// All four predict a plane a + b x + c y with integer b, c exactly.

#include <cstdint>

namespace gvkit::codec {

enum IntraMode : int {
  kIntraVertical = 0,
  kIntraHorizontal = 1,
  kIntraDc = 2,
  kIntraDiagonalDownLeft = 3,
  kIntraDiagonalDownRight = 4,
  kIntraVerticalRight = 5,
  kIntraHorizontalDown = 6,
  kIntraVerticalLeft = 7,
  kIntraHorizontalUp = 8,
  kIntraGeoPlane = 9,
  kIntraGeoVertical = 10,
  kIntraGeoHorizontal = 11,
  kIntraGeoMeanPlane = 12,
};
// 16x16 modes: 0 vertical, 1 horizontal, 2 DC, 3 plane.
constexpr int kIntra16x16Plane = 3;

constexpr int kIntra4x4ModeCount = 13;  // 9 without the geometry modes
constexpr int kIntra8x8ModeCount = 9;
constexpr int kIntra16x16ModeCount = 4;

// Neighbour samples of an N x N block: top[0..2N-1] (top and top-right), left[0..N-1], corner.
struct IntraNeighbors {
  int32_t corner = 0;
  int32_t top[32] = {};
  int32_t left[16] = {};
};

// Gathers the neighbours of the N x N block at (x0, y0) of a width x height plane (row stride
// `stride`), treating samples at or after the current block in coding order as unavailable:
// top_right_available says whether the top-right block is already coded. Substitution: a
// missing top-right repeats top[N-1]; a missing top row or left column copies the other side's
// nearest sample; with neither, every neighbour is 1 << (bit_depth - 1).
IntraNeighbors make_neighbors(const uint16_t* plane, int stride, int x0, int y0, int n,
                              bool top_available, bool left_available, bool top_right_available,
                              int bit_depth);

// Predicts an n x n block (n = 4, 8, 16) into out (row-major, n*n values). mode must be valid for
// the size (4: 0..12, 8: 0..8, 16: 0..3).
void predict_intra(int n, int mode, const IntraNeighbors& nb, int max_value, int32_t* out);
// predict_intra(4, mode, ...) for every mode 0 .. mode_count - 1 (<= kIntra4x4ModeCount) into
// out[mode], sharing the work on the neighbours.
void predict_intra4x4_modes(const IntraNeighbors& nb, int max_value, int mode_count,
                            int32_t (*out)[16]);
// The plain per-sample formulas of the same predictors, kept to check predict_intra.
void predict_intra_reference(int n, int mode, const IntraNeighbors& nb, int max_value,
                             int32_t* out);

}  // namespace gvkit::codec
