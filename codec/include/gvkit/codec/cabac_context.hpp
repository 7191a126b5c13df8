#pragma once
// CABAC probability state: H.264's 64-state LPS model (ITU-T H.264 clause 9.3, tables 9-44 and
// 9-45), shared by the encoder, the decoder and the bit-cost estimator.

#include <array>
#include <cstdint>

namespace gvkit::codec {

struct CabacContext {
  uint8_t state = 0;  // pStateIdx, 0..63 (0: p_LPS = 0.5)
  uint8_t mps = 0;    // valMPS
};

// rangeTabLPS[pStateIdx][(range >> 6) & 3].
extern const uint8_t kCabacRangeLps[64][4];
extern const uint8_t kCabacNextStateMps[64];
extern const uint8_t kCabacNextStateLps[64];
// The state transition in one table (cabac_transition): kCabacTransition[s][lps] is the next
// pStateIdx after an MPS (lps 0) or an LPS (1) in state s, plus 128 when valMPS flips (an LPS in
// state 0); the same transitions as cabac_update.
extern const uint8_t kCabacTransition[64][2];
// Cost in 1/256 bit of coding a bin in state s as the MPS ([s][0]) or the LPS ([s][1]).
extern const std::array<std::array<uint16_t, 2>, 64> kCabacBitCost;

// The transition of kCabacTransition after an MPS (is_lps 0) or an LPS (1), without a branch on
// the bin (it is unpredictable): the same state and valMPS as cabac_update.
inline void cabac_transition(CabacContext& ctx, int is_lps) {
  const uint8_t next = kCabacTransition[ctx.state][is_lps];
  ctx.mps = static_cast<uint8_t>(ctx.mps ^ (next >> 7));
  ctx.state = next & 63;
}

inline void cabac_update(CabacContext& ctx, int bin) {
  if (bin == ctx.mps) {
    ctx.state = kCabacNextStateMps[ctx.state];
  } else {
    if (ctx.state == 0) ctx.mps = static_cast<uint8_t>(1 - ctx.mps);
    ctx.state = kCabacNextStateLps[ctx.state];
  }
}

}  // namespace gvkit::codec
