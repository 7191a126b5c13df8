#pragma once
// The last step of reconstructing a block: prediction + residual, clipped to the sample range,
// written into the plane (the decoder's reconstruction and the encoder's, which must match).

#include <cstddef>
#include <cstdint>

namespace gvkit::codec {

// dst[y * dst_stride + x] = clip(pred[y * pred_stride + x] + residual[y * n + x], 0, max_value)
// for the n x n block (n = 4, 8 or 16; residual null: no residual), the sum taken without
// overflow (as 64-bit). Uses AVX2 where the processor has it; the same values as
// store_reconstruction_reference.
void store_reconstruction(int n, const int32_t* pred, int pred_stride, const int32_t* residual,
                          int max_value, uint16_t* dst, ptrdiff_t dst_stride);
void store_reconstruction_reference(int n, const int32_t* pred, int pred_stride,
                                    const int32_t* residual, int max_value, uint16_t* dst,
                                    ptrdiff_t dst_stride);

}  // namespace gvkit::codec
