#include "rdo_quantization.hpp"

#include <algorithm>
#include <array>
#include <vector>

#include "gvkit/codec/transform.hpp"
#include "gvkit/codec/transform16x16.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::codec::detail {
namespace {

// kCabacBitCost in bits: [state][0] the MPS's, [state][1] the LPS's (the same values as
// kCabacBitCost[s][b] * (1.0 / 256.0), which are exact in double).
const std::array<std::array<double, 2>, 64>& bit_cost_table() {
  static const auto table = [] {
    std::array<std::array<double, 2>, 64> t{};
    for (size_t s = 0; s < 64; ++s)
      for (size_t b = 0; b < 2; ++b) t[s][b] = kCabacBitCost[s][b] * (1.0 / 256.0);
    return t;
  }();
  return table;
}

// Bits of coding `bin` with context c in its current state.
inline double bin_bits(const std::array<std::array<double, 2>, 64>& table, const CabacContext& c,
                       int bin) {
  return table[c.state][bin != c.mps ? 1 : 0];
}

// Bypass bits of write_exp_golomb0(value, 0): 2k + 1 for the k with 2^k - 1 <= value <
// 2^(k+1) - 1.
inline double exp_golomb0_bits(uint32_t value) {
  const int k = 31 - __builtin_clz(value + 1);
  return 2.0 * k + 1.0;
}

// quantizer_step(qp)^2 for qp' 0..99, the squared error of one level step.
double squared_step(int qp) {
  static const auto table = [] {
    std::array<double, 100> t{};
    for (int q = 0; q < 100; ++q) t[static_cast<size_t>(q)] = quantizer_step(q) * quantizer_step(q);
    return t;
  }();
  return table[static_cast<size_t>(qp)];
}

// The bits of a level's magnitude and sign, as write_residual codes it, for one state of the
// level contexts (the counts of levels > 1 and equal to 1 coded before it).
class LevelBits {
 public:
  LevelBits(const std::array<std::array<double, 2>, 64>& table, const ContextSet& ctx, int cat,
            int num_gt1, int num_eq1) {
    const CabacContext& first = ctx.level[cat][num_gt1 ? 0 : std::min(4, 1 + num_eq1)];
    const CabacContext& rest = ctx.level[cat][5 + std::min(4, num_gt1)];
    one_ = 1.0 + bin_bits(table, first, 0);
    more_ = 1.0 + bin_bits(table, first, 1);
    rest1_ = bin_bits(table, rest, 1);
    rest0_ = bin_bits(table, rest, 0);
  }
  // level >= 1.
  double operator()(int32_t level) const {
    if (level == 1) return one_;
    // abs_minus1 = m >= 1: unary bins k = 1 .. min(m, kLevelPrefixMax - 1), 1 while k < m, then
    // 0 below the prefix limit, else the Exp-Golomb escape of m - kLevelPrefixMax.
    const int m = level - 1;
    if (m < kLevelPrefixMax) return more_ + (m - 1) * rest1_ + rest0_;
    return more_ + (kLevelPrefixMax - 1) * rest1_ +
           exp_golomb0_bits(static_cast<uint32_t>(m - kLevelPrefixMax));
  }

 private:
  double one_ = 0, more_ = 0, rest1_ = 0, rest0_ = 0;
};

}  // namespace

int last_significant_position(int n, const int32_t* chosen, const double* chosen_cost,
                              const double* last_extra, const double* after, double all_zero) {
  // One forward pass, the prefix sum of the costs before each position as it goes; a later
  // position of an equal total replaces an earlier one, the all-zero block only a lower total.
  double before = 0, best_total = all_zero;
  int best = -1;
  for (int j = 0; j < n; ++j) {
    if (chosen[j]) {
      const double total = before + chosen_cost[j] + last_extra[j] + after[j];
      if (total < best_total || (total == best_total && best >= 0)) {
        best_total = total;
        best = j;
      }
    }
    before += chosen_cost[j];
  }
  return best;
}

int last_significant_position_reference(int n, const int32_t* chosen, const double* chosen_cost,
                                        const double* last_extra, const double* after,
                                        double all_zero) {
  std::vector<double> before(static_cast<size_t>(n) + 1, 0.0);
  for (int i = 0; i < n; ++i) before[i + 1] = before[i] + chosen_cost[i];
  double best_total = all_zero;
  int best = -1;
  for (int j = n - 1; j >= 0; --j) {
    if (!chosen[j]) continue;
    const double total = before[j] + chosen_cost[j] + last_extra[j] + after[j];
    if (total < best_total) {
      best_total = total;
      best = j;
    }
  }
  return best;
}

void quantize_rdo(int n, const int32_t* coeffs, int qp, double lambda, const ContextSet& ctx,
                  int32_t* levels) {
  GVKIT_CHECK((n == 4 || n == 8 || n == 16) && !ctx.adaptive_levels);
  const int count = n * n, cat = residual_category(n);
  const ResidualScan& scan =
      n == 4 ? residual_scan<4>() : (n == 8 ? residual_scan<8>() : residual_scan<16>());
  int64_t numer[256];
  const int qbits = n == 16 ? quantization_numerators16x16(coeffs, qp, numer)
                            : quantization_numerators(n, coeffs, qp, numer);
  std::fill(levels, levels + count, 0);
  // The last coefficient the nearest rounding makes nonzero (numerator >= half a step).
  const int64_t half = int64_t{1} << (qbits - 1);
  int last_nearest = count - 1;
  while (last_nearest >= 0 && numer[scan.position[last_nearest]] < half) --last_nearest;
  if (last_nearest < 0) return;
  const double inv = 1.0 / static_cast<double>(int64_t{1} << qbits);
  const double unit = squared_step(qp);

  // Levels in coding order (reverse scan), each priced as if a later coefficient were the last.
  // after[i]: the distortion of leaving out every coefficient after i (summed as the loop goes).
  double chosen_cost[256], after[256], last_extra[256];
  double all_zero = 0;  // the distortion of the block coded as all zero
  int32_t chosen[256];
  const auto& table = bit_cost_table();
  int num_gt1 = 0, num_eq1 = 0;
  LevelBits level_bits(table, ctx, cat, 0, 0);
  for (int i = last_nearest; i >= 0; --i) {
    const int64_t v = numer[scan.position[i]];
    const double q = static_cast<double>(v) * inv;
    const double d0 = q * q * unit;
    after[i] = all_zero;
    all_zero += d0;
    // The last scan position codes no significance flags (it is implied when it is the last).
    const bool flags = i < count - 1;
    const int c = scan.context[i];
    const CabacContext& sig = ctx.sig[cat][c];
    const double sig0 = flags ? bin_bits(table, sig, 0) : 0.0;
    const int32_t nearest = static_cast<int32_t>((v + half) >> qbits);
    if (nearest == 0) {
      chosen[i] = 0;
      chosen_cost[i] = d0 + lambda * sig0;
      last_extra[i] = 0;
      continue;
    }
    const CabacContext& last = ctx.last[cat][c];
    const double sig1 = flags ? bin_bits(table, sig, 1) + bin_bits(table, last, 0) : 0.0;
    last_extra[i] = flags ? lambda * (bin_bits(table, last, 1) - bin_bits(table, last, 0)) : 0.0;
    double best = d0 + lambda * sig0;
    int32_t best_level = 0;
    for (int32_t l = nearest; l >= std::max(1, nearest - 1); --l) {
      const double e = q - l;
      const double cost = e * e * unit + lambda * (sig1 + level_bits(l));
      if (cost < best) {
        best = cost;
        best_level = l;
      }
    }
    chosen[i] = best_level;
    chosen_cost[i] = best;
    if (best_level == 0) continue;
    // The level contexts' indices stop changing after four levels of 1 or the first above 1
    // and four more above 1.
    const bool saturated = num_gt1 >= 4 || (num_gt1 == 0 && num_eq1 >= 3);
    if (best_level == 1)
      ++num_eq1;
    else
      ++num_gt1;
    if (!saturated || num_gt1 == 1) level_bits = LevelBits(table, ctx, cat, num_gt1, num_eq1);
  }

  // The last significant position: coefficients before it cost what was decided, the one at it
  // codes last = 1, those after it are left out (their whole magnitude is the error).
  const int best_last =
      last_significant_position(last_nearest + 1, chosen, chosen_cost, last_extra, after, all_zero);
  for (int i = 0; i <= best_last; ++i) {
    const int r = scan.position[i];
    levels[r] = coeffs[r] < 0 ? -chosen[i] : chosen[i];
  }
}

}  // namespace gvkit::codec::detail
