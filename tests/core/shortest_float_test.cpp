// write_shortest_float against std::to_chars, character for character, on every class of float:
// the notation boundaries, every digit count, special values and random bit patterns.
#include "gvkit/core/shortest_float.hpp"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace gvkit {
namespace {

std::string reference(float v) {
  char text[64];
  return std::string(text,
                     static_cast<size_t>(std::to_chars(text, text + sizeof text, v).ptr - text));
}

std::string fast(float v) {
  char text[kShortestFloatRoom + 8];
  std::memset(text, 'x', sizeof text);
  char* end = write_shortest_float(text, v);
  EXPECT_LE(end - text, static_cast<std::ptrdiff_t>(kShortestFloatRoom));
  return std::string(text, static_cast<size_t>(end - text));
}

float from_bits(uint32_t bits) {
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

// Counts the values whose texts differ, reporting the first few.
int mismatches(const std::vector<float>& values) {
  int bad = 0;
  for (const float v : values) {
    const std::string want = reference(v), got = fast(v);
    if (want != got && ++bad <= 5)
      ADD_FAILURE() << "to_chars '" << want << "', fast '" << got << "'";
  }
  return bad;
}

TEST(ShortestFloat, SpecialValuesAreWrittenAsToCharsWritesThem) {
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> values = {0.0f,
                                     -0.0f,
                                     inf,
                                     -inf,
                                     std::numeric_limits<float>::quiet_NaN(),
                                     -std::numeric_limits<float>::quiet_NaN(),
                                     std::numeric_limits<float>::min(),
                                     -std::numeric_limits<float>::min(),
                                     std::numeric_limits<float>::denorm_min(),
                                     std::numeric_limits<float>::max(),
                                     -std::numeric_limits<float>::max(),
                                     std::numeric_limits<float>::epsilon(),
                                     from_bits(0x007fffff)};  // the largest subnormal
  EXPECT_EQ(mismatches(values), 0);
  EXPECT_EQ(fast(0.5f), "0.5");
  EXPECT_EQ(fast(-123.25f), "-123.25");
  EXPECT_EQ(fast(1e-5f), "1e-05");
  EXPECT_EQ(fast(0.0001f), "1e-04");  // 5 characters against 6
  EXPECT_EQ(fast(0.001f), "0.001");   // a tie: fixed
  EXPECT_EQ(fast(1.5e-5f), "1.5e-05");
}

TEST(ShortestFloat, NotationBoundariesAndDigitCountsMatchToChars) {
  // Powers of ten and their neighbours, and 1..9-digit significands at every decimal exponent:
  // where fixed and scientific notation change places and where the digit count changes.
  std::vector<float> values;
  for (int e = -45; e <= 38; ++e) {
    const float p = std::pow(10.0f, static_cast<float>(e));
    values.push_back(p);
    values.push_back(std::nextafter(p, 0.0f));
    values.push_back(std::nextafter(p, std::numeric_limits<float>::infinity()));
    for (const double digits : {1.0, 12.0, 123.0, 1234.0, 12345.0, 123456.0, 1234567.0, 12345678.0,
                                123456789.0, 7.0, 99.0, 999999.0})
      values.push_back(static_cast<float>(digits * std::pow(10.0, e)));
  }
  std::vector<float> negated;
  for (const float v : values) negated.push_back(-v);
  EXPECT_EQ(mismatches(values), 0);
  EXPECT_EQ(mismatches(negated), 0);
}

TEST(ShortestFloat, EveryFloatOfSampledRangesMatchesToChars) {
  // Every float in [1, 1.0625), [0.001, 0.00106), and around 1e-5 and 100 (where mesh
  // coordinates, normals and texture coordinates lie), 2^16 in a row each.
  std::vector<float> values;
  for (const float start : {1.0f, 0.001f, 1e-5f, 100.0f, -0.5f}) {
    uint32_t bits;
    std::memcpy(&bits, &start, sizeof bits);
    for (uint32_t k = 0; k < (1u << 16); ++k) values.push_back(from_bits(bits + k));
  }
  EXPECT_EQ(mismatches(values), 0);
}

TEST(ShortestFloat, RandomBitPatternsMatchToChars) {
  std::mt19937 rng(7);
  std::vector<float> values;
  for (int k = 0; k < 1 << 20; ++k) values.push_back(from_bits(static_cast<uint32_t>(rng())));
  EXPECT_EQ(mismatches(values), 0);
}

}  // namespace
}  // namespace gvkit
