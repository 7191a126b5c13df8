#pragma once
// Format 1.8, the deblocking filter's per-frame parameters (the packet payload's two bytes,
// docs/bitstream.md 4.12; the filter itself: deblocking.hpp).

namespace gvkit::codec {

// beta in quarter quantizer steps, tc in sixteenths of a step; 0..255 each in a stream, 1..255
// from the encoder (EncoderOptions::check). The defaults (1.5 and 0.25 steps) were the best of
// a sweep on the ICT face: -12.9 % BD-rate against the filter off in the fast preset, -12.2 % in
// the slow one (docs/benchmarks.md, format 1.8).
struct DeblockingParams {
  int beta = 6;
  int tc = 4;  // twice that at edges of intra or TD macroblocks
};

}  // namespace gvkit::codec
