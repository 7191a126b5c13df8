#pragma once
// Cross-plane residual prediction in the macroblock layer (format 1.6, docs/bitstream.md 4.9):
// the scale's bins (H.265's log2_res_scale_abs_plus1 and res_scale_sign_flag), written before a
// Y or Z macroblock's coded block pattern by write_cbp_and_4x4_residuals.

#include "gvkit/codec/cabac_context.hpp"
#include "gvkit/codec/cabac_decoder.hpp"

namespace gvkit::codec::detail {

// log2_res_scale_abs_plus1 (0 for alpha 0, else 1 + log2 |alpha|) as a truncated unary code of
// at most 4 bins, bin i with context scale_ctx[i], then for alpha != 0 the sign (1 = negative)
// with sign_ctx. alpha is one of kCrossScales.
template <class Coder>
void write_cross_scale(Coder& coder, CabacContext* scale_ctx, CabacContext& sign_ctx, int alpha) {
  const int a = alpha < 0 ? -alpha : alpha;
  const int v = a == 0 ? 0 : (a == 1 ? 1 : (a == 2 ? 2 : (a == 4 ? 3 : 4)));
  for (int i = 0; i < 4; ++i) {
    coder.encode(scale_ctx[i], i < v);
    if (i >= v) break;
  }
  if (v > 0) coder.encode(sign_ctx, alpha < 0);
}

// The mirror of write_cross_scale (every bin string is a valid scale).
inline int read_cross_scale(CabacDecoder& dec, CabacContext* scale_ctx, CabacContext& sign_ctx) {
  int v = 0;
  while (v < 4 && dec.decode(scale_ctx[v])) ++v;
  if (v == 0) return 0;
  const int a = 1 << (v - 1);
  return dec.decode(sign_ctx) ? -a : a;
}

}  // namespace gvkit::codec::detail
