#pragma once
// Distortion measures of the encoder's decisions on blocks of B-bit samples (B <= 16): SAD of
// two sample blocks (whole-sample motion search) and SATD / SAD of a source block against an
// integer prediction (mode decisions, sub-sample refinement). The SSE2, AVX2 and AVX-512 versions
// (chosen at run time, core/cpu_features.hpp) return exactly the values of the plain *_reference
// versions, which are kept to check them.

#include <cstddef>
#include <cstdint>

namespace gvkit::codec {

// Sum over the 16x16 block of |a - b|; rows are a_stride / b_stride samples apart.
int64_t sad16x16(const uint16_t* a, ptrdiff_t a_stride, const uint16_t* b, ptrdiff_t b_stride);
int64_t sad16x16_reference(const uint16_t* a, ptrdiff_t a_stride, const uint16_t* b,
                           ptrdiff_t b_stride);

// Sum over the n x n block (n = 4, 8 or 16) of satd4x4 of each 4x4 block of src - pred, where src
// rows are src_stride samples apart and pred is row-major n * n (|src - pred| < 2^17).
int64_t satd_block(int n, const uint16_t* src, ptrdiff_t src_stride, const int32_t* pred);
int64_t satd_block_reference(int n, const uint16_t* src, ptrdiff_t src_stride, const int32_t* pred);

// satd_block(n, src, src_stride, pred) (n = 8 or 16) of the n x n prediction `first` (second
// null) or the rounded average (a + b + 1) >> 1 of `first` and `second`, whose rows are
// pred_stride samples apart: the sub-sample motion searches' cost of a vector, without forming
// pred.
int64_t satd_block_of_average(int n, const uint16_t* src, ptrdiff_t src_stride,
                              const uint16_t* first, const uint16_t* second, ptrdiff_t pred_stride);
// The same by forming pred and calling satd_block (kept to check it).
int64_t satd_block_of_average_reference(int n, const uint16_t* src, ptrdiff_t src_stride,
                                        const uint16_t* first, const uint16_t* second,
                                        ptrdiff_t pred_stride);

// Sum over the n x n block of |src - pred| (same layout as satd_block).
int64_t sad_block(int n, const uint16_t* src, ptrdiff_t src_stride, const int32_t* pred);
int64_t sad_block_reference(int n, const uint16_t* src, ptrdiff_t src_stride, const int32_t* pred);

// satd_block(4, ...) (or, with sad, sad_block(4, ...)) of the 4x4 source block against each of
// count predictions preds[0 .. count - 1] into out[i].
void distortions4x4(bool sad, const uint16_t* src, ptrdiff_t src_stride, const int32_t (*preds)[16],
                    int count, int64_t* out);
// The same for a source block given as 16 values (row-major, each within +-2^18 of every
// prediction), e.g. the source less a term every prediction shares: the temporal-difference
// reference or a cross-plane term (source - (p + t) = (source - t) - p, the same differences).
void distortions4x4_of(bool sad, const int32_t* source, const int32_t (*preds)[16], int count,
                       int64_t* out);
// The plain loops of distortions4x4_of (satd4x4 of each difference block, or its SAD).
void distortions4x4_of_reference(bool sad, const int32_t* source, const int32_t (*preds)[16],
                                 int count, int64_t* out);

}  // namespace gvkit::codec
