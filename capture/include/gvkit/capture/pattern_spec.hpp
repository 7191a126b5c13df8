#pragma once
// PatternSpec: everything that tells one pattern set from another, parsed from a name
// (create_pattern_set's grammar, pattern_set.hpp) or from a JSON file (--pattern SPEC.json), and
// written back as the canonical name. The JSON form is the escape hatch for a rig whose patterns
// no short name describes; every JSON spec has a canonical name, so sessions and stats.json
// record it in one string.
//
// JSON (every key but "family" optional; docs/real-data.md has examples):
//   {"family": "phase-shift" | "multi-frequency" | "heterodyne" | "zhang-huang" | "gray-code",
//    "steps": 4,                      N phase-shift images per frequency
//    "periods": [70, 64, 59],         fringe periods across the projector width, finest first
//    "pitch_px": 40,                  gray-code: fringe pitch in projector pixels (instead of
//                                     width / 2^bits)
//    "gray_bits": 5, "complementary": true,
//    "inverses": "interleaved" | "after",   complementary: bit, inverse, bit, ... or all bits
//                                           then all inverses
//    "order": ["white", "black", "gray", "phase"],  blocks in projection order; white and black
//                                                   (flat reference images) both or neither
//    "shift_sign": -1 | 1,            image k shows cos(phi + shift_sign * 2 pi k / N)
//    "phase_offset_deg": 0}           phi at projector column 0 (90: sine patterns)

#include <filesystem>
#include <string>
#include <vector>

#include "gvkit/core/status.hpp"

namespace gvkit::capture {

struct PatternSpec {
  enum class Family { kPhaseShift, kMultiFrequency, kHeterodyne, kZhangHuang, kGrayCode };
  Family family = Family::kPhaseShift;
  int steps = 3;
  std::vector<int> periods;  // psp, zh: one; mf: finest first, last 1; het: 2 or 3, finest first

  // Gray code + phase shift.
  int gray_bits = 0;
  bool complementary = false;   // each bit image has an inverse; bit = image > inverse
  bool inverses_after = false;  // complementary: all bit images, then all inverses
  double pitch_px = 0;          // fringe (= code stripe) pitch; 0: projector width / 2^bits
  std::string order = "pg";     // blocks in projection order: p phase, g gray, w white, b black

  // Phase-shift convention (every family but zh): image k of N shows
  // 0.5 * (1 + cos(2 pi u / pitch + phase_offset + shift_sign * 2 pi k / N)); -1 is SLStudio's.
  int shift_sign = -1;
  double phase_offset_deg = 0;

  int image_count() const;
  bool has_references() const { return order.find('w') != std::string::npos; }
  // The canonical name (pattern_set.hpp grammar); parse_pattern_name(name()) gives this back.
  std::string name() const;
  // Ok when the parameters are in range and consistent; else says which is wrong.
  Status check() const;
};

// Parses a name of the grammar in pattern_set.hpp. Fails naming the name and the part that does
// not parse or is out of range.
Result<PatternSpec> parse_pattern_name(const std::string& name);
// Reads a JSON spec (see above). Fails naming the file and the key.
Result<PatternSpec> read_pattern_spec(const std::filesystem::path& path);

}  // namespace gvkit::capture
