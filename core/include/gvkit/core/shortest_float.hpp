#pragma once
// The shortest decimal text of a float that reads back as the same float, for the ASCII mesh
// writers (PLY, OBJ): the same characters as std::to_chars(first, last, value) (the shortest
// digits closest to the value, in fixed or scientific notation, whichever is shorter, fixed on a
// tie; "inf", "nan", "-0", subnormals), about 1.6x faster. The digits come from fmt's Dragonbox
// (fmt::detail::dragonbox::to_decimal, the algorithm fmt itself formats floats with); the
// notation is chosen and written here; values whose fixed form would need zeros after the
// digits (|v| >= 10^digits), zeros, subnormals, infinities and NaNs are handed to
// std::to_chars. `ShortestFloat.*` tests compare the two on every float class; every one of the
// 2^32 bit patterns was compared once (docs/benchmarks.md, "ASCII export").

#include <cstddef>

namespace gvkit {

// Bytes write_shortest_float may write at `out`: the text is at most 15 characters
// ("-1.17549435e-38"), and fixed-size copies write up to 27 (the bytes past the text's end are
// then left overwritten).
inline constexpr size_t kShortestFloatRoom = 32;

// Writes the text of `value` at `out` (kShortestFloatRoom bytes available; those past the
// returned end may be overwritten) and returns the end of the text.
char* write_shortest_float(char* out, float value);

}  // namespace gvkit
