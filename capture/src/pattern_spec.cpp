#include "gvkit/capture/pattern_spec.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <regex>

#include <nlohmann/json.hpp>

#include "gvkit/core/json_io.hpp"

namespace gvkit::capture {
namespace {

using Family = PatternSpec::Family;

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", v);
  return text;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out(1);
  for (char c : s) {
    if (c == sep)
      out.emplace_back();
    else
      out.back() += c;
  }
  return out;
}

bool is_int(const std::string& s) {
  return !s.empty() && s.size() <= 6 && std::all_of(s.begin(), s.end(), ::isdigit);
}
bool is_number(const std::string& s) {
  return std::regex_match(s, std::regex(R"(\d{1,6}(\.\d{1,6})?)"));
}

}  // namespace

int PatternSpec::image_count() const {
  switch (family) {
    case Family::kPhaseShift:
      return steps;
    case Family::kMultiFrequency:
    case Family::kHeterodyne:
      return steps * static_cast<int>(periods.size());
    case Family::kZhangHuang:
      return 3;
    case Family::kGrayCode:
      return steps + gray_bits * (complementary ? 2 : 1) + (has_references() ? 2 : 0);
  }
  return 0;
}

std::string PatternSpec::name() const {
  const int first = periods.empty() ? 0 : periods[0];
  std::string n;
  switch (family) {
    case Family::kPhaseShift:
      n = "psp" + std::to_string(steps) + "-f" + std::to_string(first);
      break;
    case Family::kMultiFrequency:
    case Family::kHeterodyne:
      n = (family == Family::kHeterodyne ? "het" : "mf") + std::to_string(steps);
      for (int p : periods) n += "-f" + std::to_string(p);
      break;
    case Family::kZhangHuang:
      return "zh-f" + std::to_string(first);
    case Family::kGrayCode:
      n = std::string(complementary ? "c" : "") + "gray" + std::to_string(gray_bits) + "-psp" +
          std::to_string(steps);
      if (!periods.empty()) n += "-f" + std::to_string(periods[0]);
      if (pitch_px > 0) n += "-p" + number(pitch_px);
      if (order != "pg") n += "-o" + order;
      if (inverses_after) n += "-ia";
      break;
  }
  if (shift_sign > 0) n += "-pos";
  if (phase_offset_deg != 0) n += "-ph" + number(phase_offset_deg);
  return n;
}

Status PatternSpec::check() const {
  auto bad = [&](const std::string& why) { return invalid_argument(why); };
  if (family != Family::kZhangHuang && (steps < 3 || steps > 64))
    return bad("needs 3..64 steps, has " + std::to_string(steps));
  for (int p : periods)
    if (p < 1 || p > 4096) return bad("periods must be 1..4096, has " + std::to_string(p));
  if (shift_sign != 1 && shift_sign != -1) return bad("shift sign must be -1 or +1");
  if (!(phase_offset_deg >= 0 && phase_offset_deg < 360))
    return bad("phase offset must be in [0, 360) degrees");
  switch (family) {
    case Family::kPhaseShift:
    case Family::kZhangHuang:
      if (periods.size() != 1) return bad("needs one frequency");
      if (family == Family::kZhangHuang && (shift_sign != -1 || phase_offset_deg != 0))
        return bad("zh takes no shift sign or phase offset");
      break;
    case Family::kMultiFrequency:
      if (periods.size() < 2 || periods.size() > 3) return bad("needs 2 or 3 frequencies");
      if (periods.back() != 1) return bad("the last (coarsest) frequency must be f1");
      for (size_t i = 0; i + 1 < periods.size(); ++i)
        if (periods[i] <= periods[i + 1])
          return bad("frequencies must decrease from finest to f1 (at most 4096 periods)");
      break;
    case Family::kHeterodyne: {
      if (periods.size() < 2 || periods.size() > 3) return bad("needs 2 or 3 frequencies");
      for (size_t i = 0; i + 1 < periods.size(); ++i)
        if (periods[i] <= periods[i + 1]) return bad("frequencies must decrease, finest first");
      // The beat of the beats must be one period across the projector: then it is absolute.
      const int beat = periods.size() == 2
                           ? periods[0] - periods[1]
                           : std::abs((periods[0] - periods[1]) - (periods[1] - periods[2]));
      if (beat != 1)
        return bad(periods.size() == 2
                       ? "two heterodyne frequencies must differ by 1 period (e.g. f16-f15)"
                       : "three heterodyne frequencies P1 > P2 > P3 need (P1 - P2) - (P2 - P3) "
                         "= +-1 (e.g. f70-f64-f59: 6 - 5 = 1)");
      break;
    }
    case Family::kGrayCode: {
      if (gray_bits < 1 || gray_bits > 12) return bad("needs 1..12 Gray-code bits");
      if (periods.size() > 1) return bad("takes at most one frequency");
      if (!periods.empty() && pitch_px > 0) return bad("give a pitch or a frequency, not both");
      if (!periods.empty() && periods[0] > (1 << gray_bits))
        return bad(std::to_string(gray_bits) + " bits cannot number " + std::to_string(periods[0]) +
                   " periods");
      if (pitch_px < 0 || (pitch_px > 0 && pitch_px < 2)) return bad("pitch must be >= 2 px");
      std::string sorted = order;
      std::sort(sorted.begin(), sorted.end());
      if (sorted != "gp" && sorted != "bgpw")
        return bad("order '" + order +
                   "' must hold p (phase) and g (gray) once each, and w and b (white, black "
                   "references) both or neither");
      if (inverses_after && !complementary) return bad("inverses need a complementary code");
      break;
    }
  }
  return Status::ok();
}

Result<PatternSpec> parse_pattern_name(const std::string& name) {
  const std::string where = "pattern set '" + name + "'";
  auto bad = [&](const std::string& why) -> Status { return invalid_argument(where + ": " + why); };
  const std::vector<std::string> t = split(name, '-');
  PatternSpec s;
  size_t i = 1;
  std::smatch m;
  auto periods_from = [&](size_t min, size_t max) -> Status {
    while (i < t.size() && t[i].size() > 1 && t[i][0] == 'f' && is_int(t[i].substr(1)))
      s.periods.push_back(std::stoi(t[i++].substr(1)));
    if (s.periods.size() < min || s.periods.size() > max)
      return bad(min == max ? "needs -f<P> (periods across the projector)"
                            : "needs " + std::to_string(min) + ".." + std::to_string(max) +
                                  " frequencies -f<P>");
    return Status::ok();
  };
  const std::string& head = t[0];
  if (std::regex_match(head, m, std::regex(R"(psp(\d{1,4}))"))) {
    s.family = Family::kPhaseShift;
    s.steps = std::stoi(m[1]);
    GVKIT_RETURN_IF_ERROR(periods_from(1, 1));
  } else if (std::regex_match(head, m, std::regex(R"((mf|het)(\d{1,4}))"))) {
    s.family = m[1] == "mf" ? Family::kMultiFrequency : Family::kHeterodyne;
    s.steps = std::stoi(m[2]);
    GVKIT_RETURN_IF_ERROR(periods_from(2, 3));
  } else if (head == "zh") {
    s.family = Family::kZhangHuang;
    GVKIT_RETURN_IF_ERROR(periods_from(1, 1));
  } else if (std::regex_match(head, m, std::regex(R"((c?)gray(\d{1,4}))"))) {
    s.family = Family::kGrayCode;
    s.complementary = m[1] == "c";
    s.gray_bits = std::stoi(m[2]);
    if (i >= t.size() || !std::regex_match(t[i], m, std::regex(R"(psp(\d{1,4}))")))
      return bad("needs -psp<N> after the Gray code");
    s.steps = std::stoi(m[1]);
    ++i;
    GVKIT_RETURN_IF_ERROR(periods_from(0, 1));
  } else {
    return bad("unknown name");
  }
  const bool gray = s.family == Family::kGrayCode;
  for (; i < t.size(); ++i) {
    const std::string& tok = t[i];
    if (tok == "pos" && s.family != Family::kZhangHuang) {
      s.shift_sign = 1;
    } else if (tok.rfind("ph", 0) == 0 && is_number(tok.substr(2)) &&
               s.family != Family::kZhangHuang) {
      s.phase_offset_deg = std::stod(tok.substr(2));
    } else if (gray && tok.size() > 1 && tok[0] == 'p' && is_number(tok.substr(1))) {
      s.pitch_px = std::stod(tok.substr(1));
    } else if (gray && tok.size() > 1 && tok[0] == 'o' &&
               tok.find_first_not_of("pgwb", 1) == std::string::npos) {
      s.order = tok.substr(1);
    } else if (gray && tok == "ia") {
      s.inverses_after = true;
    } else {
      return bad("unknown part '" + tok + "'");
    }
  }
  Status ok = s.check();
  if (!ok) return bad(ok.message());
  return s;
}

Result<PatternSpec> read_pattern_spec(const std::filesystem::path& path) {
  GVKIT_ASSIGN_OR_RETURN(nlohmann::json j, read_json(path));
  const std::string where = path.string();
  auto bad = [&](const std::string& why) -> Status { return invalid_argument(where + ": " + why); };
  if (!j.is_object()) return bad("a pattern spec is a JSON object");
  static const std::vector<std::string> known = {
      "family",   "steps", "periods",    "pitch_px",         "gray_bits", "complementary",
      "inverses", "order", "shift_sign", "phase_offset_deg", "comment"};
  for (const auto& item : j.items())
    if (std::find(known.begin(), known.end(), item.key()) == known.end())
      return bad("unknown key '" + item.key() +
                 "'; known: family, steps, periods, pitch_px, "
                 "gray_bits, complementary, inverses, order, shift_sign, phase_offset_deg");
  PatternSpec s;
  try {
    const std::string family = j.at("family").get<std::string>();
    if (family == "phase-shift")
      s.family = Family::kPhaseShift;
    else if (family == "multi-frequency")
      s.family = Family::kMultiFrequency;
    else if (family == "heterodyne")
      s.family = Family::kHeterodyne;
    else if (family == "zhang-huang")
      s.family = Family::kZhangHuang;
    else if (family == "gray-code")
      s.family = Family::kGrayCode;
    else
      return bad("family '" + family +
                 "' is not phase-shift, multi-frequency, heterodyne, zhang-huang or gray-code");
    s.steps = j.value("steps", s.family == Family::kGrayCode ? 4 : 3);
    if (j.contains("periods")) {
      const auto& p = j["periods"];
      s.periods = p.is_array() ? p.get<std::vector<int>>() : std::vector<int>{p.get<int>()};
    }
    s.pitch_px = j.value("pitch_px", 0.0);
    s.complementary = j.value("complementary", false);
    const std::string inverses = j.value("inverses", std::string("interleaved"));
    if (inverses != "interleaved" && inverses != "after")
      return bad("inverses must be \"interleaved\" or \"after\", is \"" + inverses + "\"");
    s.inverses_after = inverses == "after";
    if (j.contains("order")) {
      s.order.clear();
      for (const auto& block : j["order"]) {
        const std::string b = block.get<std::string>();
        if (b == "phase" || b == "gray" || b == "white" || b == "black")
          s.order += b[0] == 'w' ? 'w' : b[0] == 'b' ? 'b' : b[0];
        else
          return bad("order entry \"" + b + "\" is not phase, gray, white or black");
      }
    }
    s.shift_sign = j.value("shift_sign", -1);
    s.phase_offset_deg = j.value("phase_offset_deg", 0.0);
    if (s.family == Family::kGrayCode) {
      if (j.contains("gray_bits")) {
        s.gray_bits = j["gray_bits"].get<int>();
      } else if (s.periods.size() == 1) {
        while ((1 << s.gray_bits) < s.periods[0]) ++s.gray_bits;
      } else {
        return bad("gray-code needs gray_bits (or periods, from which the bits follow)");
      }
    } else if (j.contains("gray_bits") || j.contains("pitch_px") || j.contains("order") ||
               j.contains("complementary")) {
      return bad("gray_bits, pitch_px, order and complementary belong to the gray-code family");
    }
  } catch (const nlohmann::json::exception& e) {
    return bad(std::string("malformed pattern spec: ") + e.what());
  }
  Status ok = s.check();
  if (!ok) return bad(ok.message());
  return s;
}

}  // namespace gvkit::capture
