// CABAC engine: encoder and decoder mirror each other on random bins (context-coded, bypass,
// terminating), adapt to skewed sources, and the bit counter agrees with the real size.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "gvkit/codec/cabac_decoder.hpp"
#include "gvkit/codec/cabac_encoder.hpp"

namespace gvkit::codec {
namespace {

struct Bin {
  int kind;  // 0 context, 1 bypass, 2 terminate(0)
  int ctx;
  int value;
};

std::vector<Bin> random_bins(uint32_t seed, int count, double p_one) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Bin> bins;
  for (int i = 0; i < count; ++i) {
    const double k = u(rng);
    const int kind = k < 0.8 ? 0 : (k < 0.98 ? 1 : 2);
    const int ctx = static_cast<int>(u(rng) * 8);
    const int value = kind == 2 ? 0 : (u(rng) < p_one * (ctx + 1) / 8.0 ? 1 : 0);
    bins.push_back({kind, ctx, value});
  }
  return bins;
}

// The bins coded with fresh contexts, then the terminating 1 and finish(), or without it
// finish_unterminated() (the segments of every 2.0 packet).
std::string encode_bins(const std::vector<Bin>& bins, bool terminated) {
  CabacEncoder enc;
  CabacContext ctx[8];
  for (const Bin& b : bins) {
    if (b.kind == 0) enc.encode(ctx[b.ctx], b.value);
    if (b.kind == 1) enc.encode_bypass(b.value);
    if (b.kind == 2) enc.encode_terminate(0);
  }
  if (!terminated) return enc.finish_unterminated();
  enc.encode_terminate(1);
  return enc.finish();
}

// Decodes `bins` from bytes (ASSERTs each value), then the terminating 1 when `terminated`;
// expects the decoder within its allowance past the end.
void expect_decodes(const std::string& bytes, const std::vector<Bin>& bins, bool terminated,
                    uint32_t seed) {
  CabacDecoder dec(bytes);
  CabacContext ctx[8];
  for (size_t i = 0; i < bins.size(); ++i) {
    const Bin& b = bins[i];
    int v = b.kind == 0 ? dec.decode(ctx[b.ctx])
                        : (b.kind == 1 ? dec.decode_bypass() : dec.decode_terminate());
    ASSERT_EQ(v, b.value) << "seed " << seed << " bin " << i;
  }
  if (terminated) {
    EXPECT_EQ(dec.decode_terminate(), 1) << "seed " << seed;
  }
  EXPECT_FALSE(dec.overrun()) << "seed " << seed;
}

TEST(CabacRoundTrip, RandomBinsDecodeToWhatWasEncoded) {
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    const auto bins = random_bins(seed, 5000, seed % 2 ? 0.1 : 0.7);
    expect_decodes(encode_bins(bins, true), bins, true, seed);
  }
}

// finish_unterminated (2.0 segments): the same bins decode from fewer bytes than with the
// terminating bin and finish() (never more), with the decoder inside its allowance past the end,
// for sequences of every length down to none.
TEST(CabacRoundTrip, UnterminatedFlushDecodesFromFewerBytes) {
  size_t unterminated_total = 0, standard_total = 0;
  int empty = 0;
  for (uint32_t seed = 1; seed <= 400; ++seed) {
    const int count = seed <= 40 ? static_cast<int>(seed) - 1 : static_cast<int>(seed * 7 % 900);
    const auto bins = random_bins(seed, count, seed % 3 == 0 ? 0.02 : 0.4);
    const std::string standard = encode_bins(bins, true), unterminated = encode_bins(bins, false);
    ASSERT_LE(unterminated.size(), standard.size()) << "seed " << seed;
    unterminated_total += unterminated.size();
    standard_total += standard.size();
    empty += unterminated.empty();
    expect_decodes(unterminated, bins, false, seed);
  }
  // About a byte a segment: at least half a byte on average.
  EXPECT_LE(2 * unterminated_total + 400, 2 * standard_total);
  EXPECT_GT(empty, 0);  // a run of likely bins can end as no bytes at all
}

TEST(CabacRoundTrip, SkewedSourceCompressesNearEntropyAndCounterAgrees) {
  std::mt19937 rng(7);
  std::bernoulli_distribution one(0.05);
  CabacEncoder enc;
  CabacBitCounter counter;
  CabacContext a, b;
  const int n = 100000;
  std::vector<int> values(n);
  for (int i = 0; i < n; ++i) {
    values[i] = one(rng) ? 1 : 0;
    enc.encode(a, values[i]);
    counter.encode(b, values[i]);
  }
  enc.encode_terminate(1);
  const double bits = enc.finish().size() * 8.0;
  const double entropy = n * -(0.05 * std::log2(0.05) + 0.95 * std::log2(0.95));
  EXPECT_LT(bits, entropy * 1.06);
  EXPECT_NEAR(counter.bits(), bits, bits * 0.03);
}

// The counter adapts a context exactly as the encoder (cabac_update) does, and adds the cost of
// the bin in the state it was coded in, for every state, MPS and bin.
TEST(CabacRoundTrip, CounterAdaptsContextsAsTheEncoder) {
  for (int state = 0; state < 64; ++state)
    for (int mps = 0; mps < 2; ++mps)
      for (int bin = 0; bin < 2; ++bin) {
        CabacContext counted{static_cast<uint8_t>(state), static_cast<uint8_t>(mps)};
        CabacContext updated = counted;
        CabacBitCounter counter;
        counter.encode(counted, bin);
        cabac_update(updated, bin);
        EXPECT_EQ(counted.state, updated.state) << state << " " << mps << " " << bin;
        EXPECT_EQ(counted.mps, updated.mps) << state << " " << mps << " " << bin;
        EXPECT_EQ(counter.cost_256(), kCabacBitCost[state][bin != mps ? 1 : 0]);
      }
}

TEST(CabacRoundTrip, GarbageNeverReadsOutOfBoundsAndReportsOverrun) {
  const std::string bytes = "\xff\x00\x13";
  CabacDecoder dec(bytes);
  CabacContext ctx;
  for (int i = 0; i < 1000; ++i) dec.decode(ctx);
  EXPECT_TRUE(dec.overrun());
}

}  // namespace
}  // namespace gvkit::codec
