#include "gvkit/core/shortest_float.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cstdint>
#include <cstring>

namespace gvkit {
namespace {

constexpr char kDigitPairs[201] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

constexpr uint32_t kPowersOf10[10] = {1,      10,      100,      1000,      10000,
                                      100000, 1000000, 10000000, 100000000, 1000000000};

// Decimal digits of v (1..10).
int digit_count(uint32_t v) {
  const int bits = 32 - __builtin_clz(v | 1);
  const int n = (bits * 1233) >> 12;  // floor(log10(2^bits)), 1233 / 4096 ~ log10(2)
  return n + (v >= kPowersOf10[n] ? 1 : 0);
}

// The nine decimal digits of v < 10^9, zero-padded, at out[0, 9) (fixed work, no branch).
void write_nine_digits(char* out, uint32_t v) {
  const uint32_t high = v / 10000, low = v % 10000;  // high < 100000
  out[0] = static_cast<char>('0' + high / 10000);
  const uint32_t middle = high % 10000;
  std::memcpy(out + 1, kDigitPairs + 2 * (middle / 100), 2);
  std::memcpy(out + 3, kDigitPairs + 2 * (middle % 100), 2);
  std::memcpy(out + 5, kDigitPairs + 2 * (low / 100), 2);
  std::memcpy(out + 7, kDigitPairs + 2 * (low % 100), 2);
}

char* to_chars_fallback(char* out, float value) {
  return std::to_chars(out, out + kShortestFloatRoom, value).ptr;
}

}  // namespace

char* write_shortest_float(char* out, float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  const uint32_t exponent_bits = (bits >> 23) & 0xff;
  // Zeros, subnormals, infinities and NaNs.
  if (exponent_bits == 0 || exponent_bits == 0xff) return to_chars_fallback(out, value);
  // value = +-significand x 10^exponent with the fewest digits (a float has at most 9).
  const auto decimal = fmt::detail::dragonbox::to_decimal(value);
  // Positive exponents: the fixed form would end in zeros that std::to_chars may write otherwise.
  if (decimal.exponent > 0) return to_chars_fallback(out, value);
  const uint32_t significand = decimal.significand;
  const int n = digit_count(significand);
  const int fraction = -decimal.exponent;  // digits after the point in fixed notation
  *out = '-';
  out += bits >> 31;
  // The n digits at digits[0, n), in a buffer long enough for the fixed-size copies below
  // (which copy a few characters past the text; the caller's room holds them).
  char padded[40] = {};
  write_nine_digits(padded, significand);
  const char* digits = padded + 9 - n;
  if (fraction < n) {
    // Fixed notation with the point among the digits (n + 1 characters, or n without a
    // fraction) is always shorter than scientific (n + 5).
    std::memcpy(out, digits, 16);
    if (fraction == 0) return out + n;
    out[n - fraction] = '.';
    std::memcpy(out + n - fraction + 1, digits + n - fraction, 16);
    return out + n + 1;
  }
  // "0." + (fraction - n) zeros + the digits (2 + fraction characters) against scientific
  // notation: the digits with a point after the first, 'e', the sign and two exponent digits
  // (|exponent| <= 45 for a float): n + (n > 1) + 4 characters. Fixed wins ties.
  if (2 + fraction <= n + (n > 1 ? 1 : 0) + 4) {
    std::memcpy(out, "0.000", 5);  // fraction - n <= 3 zeros here
    std::memcpy(out + 2 + fraction - n, digits, 16);
    return out + 2 + fraction;
  }
  out[0] = digits[0];
  out[1] = '.';
  std::memcpy(out + 2, digits + 1, 8);
  char* p = out + (n > 1 ? n + 1 : 1);
  const int scientific_exponent = decimal.exponent + n - 1;
  p[0] = 'e';
  p[1] = scientific_exponent < 0 ? '-' : '+';
  const int magnitude = scientific_exponent < 0 ? -scientific_exponent : scientific_exponent;
  std::memcpy(p + 2, kDigitPairs + 2 * magnitude, 2);
  return p + 4;
}

}  // namespace gvkit
