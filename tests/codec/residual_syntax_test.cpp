// The residual syntax's tables and helpers (codec/src/macroblock_syntax.hpp): the per-size scan
// tables against the scan and context functions they are built from, the adaptive Exp-Golomb
// order against its definition, and the bit counter's local copy in write_residual against a
// coder that is written through in place.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <type_traits>
#include <vector>

#include "gvkit/codec/cabac_encoder.hpp"
#include "macroblock_syntax.hpp"

namespace gvkit::codec::detail {
namespace {

template <int N>
void expect_scan_tables() {
  const ResidualScan& scan = residual_scan<N>();
  for (int i = 0; i < N * N; ++i) {
    EXPECT_EQ(scan.position[i], scan_position(N, i)) << N << "x" << N << " scan index " << i;
    EXPECT_EQ(scan.context[i], sig_context(N, i)) << N << "x" << N << " scan index " << i;
  }
}

TEST(ResidualSyntax, ScanTablesHoldTheScanAndTheSignificanceContexts) {
  expect_scan_tables<4>();
  expect_scan_tables<8>();
  expect_scan_tables<16>();
}

TEST(ResidualSyntax, AdaptiveOrderIsTheLargestOrderWhoseDoubleFitsTheMean) {
  // The definition: the largest k <= 20 with 2^(k + 1) <= mean16 / 16, or 0.
  const auto definition = [](uint32_t mean16) {
    const uint32_t mean = mean16 >> 4;
    int k = 0;
    while (k < 20 && (2u << k) <= mean) ++k;
    return k;
  };
  std::vector<uint32_t> values;
  for (uint32_t v = 0; v < 70000; ++v) values.push_back(v);
  for (int b = 0; b < 32; ++b)
    for (int d = -2; d <= 2; ++d) values.push_back((uint32_t{1} << b) + static_cast<uint32_t>(d));
  values.push_back(UINT32_MAX);
  for (const uint32_t v : values) EXPECT_EQ(adaptive_order(v), definition(v)) << "mean16 " << v;
}

// A coder written through in place (not trivially copyable): write_residual's reference path.
class InPlaceCounter {
 public:
  InPlaceCounter() = default;
  ~InPlaceCounter() {}  // user-provided: not trivially copyable
  void encode(CabacContext& ctx, int bin) { counter_.encode(ctx, bin); }
  void encode_bypass(int bin) { counter_.encode_bypass(bin); }
  int64_t cost_256() const { return counter_.cost_256(); }

 private:
  CabacBitCounter counter_;
};

static_assert(!std::is_trivially_copyable_v<InPlaceCounter>);
static_assert(std::is_trivially_copyable_v<CabacBitCounter>);

TEST(ResidualSyntax, TheCounterWorkedOnAsACopyCountsAsInPlace) {
  std::mt19937 rng(7);
  for (const bool adaptive : {false, true})
    for (const int n : {4, 8, 16}) {
      ContextSet a{}, b{};
      a.adaptive_levels = b.adaptive_levels = adaptive;
      CabacBitCounter copied;
      InPlaceCounter in_place;
      for (int block = 0; block < 200; ++block) {
        std::vector<int32_t> levels(static_cast<size_t>(n * n), 0);
        std::geometric_distribution<int> magnitude(0.3);
        const int nonzero = 1 + static_cast<int>(rng() % static_cast<uint32_t>(n * n));
        for (int k = 0; k < nonzero; ++k) {
          const int32_t m = 1 + magnitude(rng) * (rng() % 8 == 0 ? 40 : 1);
          levels[rng() % levels.size()] = rng() % 2 ? m : -m;
        }
        if (std::all_of(levels.begin(), levels.end(), [](int32_t v) { return v == 0; }))
          levels[0] = 1;
        write_residual(copied, a, levels.data(), n);
        write_residual(in_place, b, levels.data(), n);
        ASSERT_EQ(copied.cost_256(), in_place.cost_256()) << n << "x" << n << " block " << block;
      }
      for (size_t c = 0; c < sizeof(a.sig) / sizeof(CabacContext); ++c) {
        EXPECT_EQ((&a.sig[0][0])[c].state, (&b.sig[0][0])[c].state);
        EXPECT_EQ((&a.sig[0][0])[c].mps, (&b.sig[0][0])[c].mps);
      }
      for (int cat = 0; cat < 3; ++cat) EXPECT_EQ(a.level_mean16[cat], b.level_mean16[cat]);
    }
}

}  // namespace
}  // namespace gvkit::codec::detail
