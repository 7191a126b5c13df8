#include "work_summary.hpp"

#include <cmath>
#include <cstdio>
#include <map>

#include <nlohmann/json.hpp>

#include "gvkit/core/json_io.hpp"

namespace gvkit::tools {
namespace fs = std::filesystem;
namespace {

std::string format(const char* fmt, double a, double b = 0, double c = 0, double d = 0,
                   double e = 0) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), fmt, a, b, c, d, e);
  return buf;
}

double number(const nlohmann::json& j, const char* key, double fallback = NAN) {
  if (!j.is_object() || !j.contains(key)) return fallback;
  const auto& v = j[key];
  if (v.is_number()) return v.get<double>();
  if (v.is_string() && v.get<std::string>() == "inf") return INFINITY;
  return fallback;
}

// Reads path when it exists: nullopt-like empty json when absent, a Status when unreadable.
Result<nlohmann::json> read_if_present(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return nlohmann::json();
  GVKIT_ASSIGN_OR_RETURN(nlohmann::json j, read_json(path));
  if (!j.is_object()) return corrupt_data(path.string() + ": not a JSON object");
  return j;
}

const nlohmann::json& summary_of(const nlohmann::json& stats) {
  static const nlohmann::json kEmpty = nlohmann::json::object();
  return stats.contains("summary") && stats["summary"].is_object() ? stats["summary"] : kEmpty;
}

// "frame N: message" for every failed frame entry (ok == false, or an "error" field).
std::vector<std::string> failed_frames(const nlohmann::json& stats) {
  std::vector<std::string> out;
  if (!stats.contains("frames") || !stats["frames"].is_array()) return out;
  for (const auto& f : stats["frames"]) {
    if (!f.is_object()) continue;
    const bool failed = (f.contains("ok") && f["ok"] == false) || f.contains("error") ||
                        (f.contains("status") && f["status"] != "ok");
    if (!failed) continue;
    std::string why = f.value("error", std::string());
    if (why.empty() && f.contains("status") && f["status"].is_string()) why = f["status"];
    const int64_t index = f.value("index", f.value("frame", int64_t{-1}));
    const std::string prefix = "frame " + std::to_string(index) + ": ";
    out.push_back(why.rfind(prefix, 0) == 0 ? why : prefix + why);
  }
  return out;
}

}  // namespace

Result<std::vector<StageSummary>> summarize_work_folder(const fs::path& work) {
  std::error_code ec;
  if (!fs::is_directory(work, ec)) return not_found(work.string() + ": no such folder");
  std::vector<StageSummary> stages;

  // run.json: the session a run read (a user's folder, or WORK/session) and the stage times.
  GVKIT_ASSIGN_OR_RETURN(nlohmann::json run, read_if_present(work / "run.json"));
  fs::path session_dir = work / "session";
  std::string session_stage = "synth";
  if (!fs::exists(session_dir / "session.json", ec) && run.contains("session") &&
      run["session"].is_string()) {
    session_dir = run["session"].get<std::string>();
    session_stage = "session";
  }
  GVKIT_ASSIGN_OR_RETURN(nlohmann::json session, read_if_present(session_dir / "session.json"));
  if (!session.is_null()) {
    StageSummary s;
    s.stage = session_stage;
    if (session.contains("frames") && session["frames"].is_array())
      s.frames_out = static_cast<int64_t>(session["frames"].size());
    if (session.contains("image_size") && session["image_size"].is_array() &&
        session["image_size"].size() == 2)
      s.figures = format("%.0fx%.0f fringe images", session["image_size"][0].get<double>(),
                         session["image_size"][1].get<double>());
    if (session.contains("pattern") && session["pattern"].is_object() &&
        session["pattern"].contains("name") && session["pattern"]["name"].is_string())
      s.figures += ", pattern " + session["pattern"]["name"].get<std::string>();
    const double dropped = number(session, "dropped_frames", 0);
    if (dropped > 0) s.figures += format(", %.0f dropped", dropped);
    stages.push_back(s);
  }

  GVKIT_ASSIGN_OR_RETURN(nlohmann::json scans, read_if_present(work / "scans" / "stats.json"));
  if (!scans.is_null()) {
    const auto& sum = summary_of(scans);
    StageSummary s;
    s.stage = "reconstruct";
    s.frames_in = static_cast<int64_t>(number(sum, "frames", -1));
    s.frames_out = scans.contains("frames") ? static_cast<int64_t>(scans["frames"].size()) : -1;
    if (std::isfinite(number(sum, "rms_depth_error_mm")))
      s.figures = format("RMS depth error %.4f mm (face interior %.4f mm), max %.3f mm; ",
                         number(sum, "rms_depth_error_mm"), number(sum, "face_interior_rms_mm"),
                         number(sum, "max_depth_error_mm"));
    s.figures += format("valid share %.3f", number(sum, "mean_valid_share"));
    stages.push_back(s);
  }

  GVKIT_ASSIGN_OR_RETURN(nlohmann::json faces, read_if_present(work / "faces" / "stats.json"));
  if (!faces.is_null()) {
    const auto& sum = summary_of(faces);
    StageSummary s;
    s.stage = "clean";
    s.frames_in = static_cast<int64_t>(number(sum, "frames", -1));
    s.frames_out = static_cast<int64_t>(number(sum, "ok", -1));
    s.failures = failed_frames(faces);
    s.figures = format("%.0f failed, mean %.0f ms per frame", number(sum, "failed", 0),
                       number(sum, "mean_frame_ms", 0));
    stages.push_back(s);
  }

  GVKIT_ASSIGN_OR_RETURN(nlohmann::json gv, read_if_present(work / "gv" / "stats.json"));
  if (!gv.is_null()) {
    const auto& sum = summary_of(gv);
    StageSummary s;
    s.stage = "map";
    s.frames_in = static_cast<int64_t>(number(sum, "frames", -1));
    s.frames_out = static_cast<int64_t>(number(sum, "mapped", -1));
    s.failures = failed_frames(gv);
    s.figures =
        format("flips %.0f, feature drift %.2f px (key points %.2f, max %.2f)",
               number(sum, "flipped_total", 0), number(sum, "feature_drift_px_mean"),
               number(sum, "key_feature_drift_px_mean"), number(sum, "key_feature_drift_px_max"));
    if (std::isfinite(number(sum, "temporal_mse_mean_mm2")))
      s.figures += format(", temporal MSE %.4f mm^2", number(sum, "temporal_mse_mean_mm2"));
    stages.push_back(s);
  }

  GVKIT_ASSIGN_OR_RETURN(nlohmann::json enc, read_if_present(work / "face.gvid.stats.json"));
  if (!enc.is_null()) {
    const auto& sum = summary_of(enc);
    StageSummary s;
    s.stage = "encode";
    s.frames_in = s.frames_out = static_cast<int64_t>(number(sum, "frames", -1));
    s.figures = format("%.4f bits/vertex/frame, PSNR %.2f dB, max error %.4f mm, ",
                       number(sum, "bits_per_vertex_per_frame"), number(sum, "psnr_db"),
                       number(sum, "max_mm"));
    if (std::isfinite(number(sum, "normal_p95_deg")))  // streams encoded since the surface metrics
      s.figures += format("normal error p95 %.2f deg, Hausdorff %.3f mm, ",
                          number(sum, "normal_p95_deg"), number(sum, "hausdorff_mm"));
    s.figures += format("%.0f bytes", number(sum, "file_bytes"));
    stages.push_back(s);
  }

  GVKIT_ASSIGN_OR_RETURN(nlohmann::json dec, read_if_present(work / "decoded" / "stats.json"));
  if (!dec.is_null()) {
    const auto& sum = summary_of(dec);
    StageSummary s;
    s.stage = "decode";
    s.frames_in = static_cast<int64_t>(number(sum, "frames", -1));
    s.frames_out = s.frames_in - static_cast<int64_t>(number(sum, "failed_frames", 0));
    s.failures = failed_frames(dec);
    s.figures = format("%.1f frames/s", number(sum, "decode_fps"));
    stages.push_back(s);
  }

  GVKIT_ASSIGN_OR_RETURN(nlohmann::json render, read_if_present(work / "face.stats.json"));
  if (!render.is_null()) {
    const auto& sum = summary_of(render);
    StageSummary s;
    s.stage = "render";
    s.frames_out = static_cast<int64_t>(number(sum, "rendered", -1));
    s.frames_in = s.frames_out + static_cast<int64_t>(number(sum, "failed", 0));
    s.figures = format("%.1f frames/s", number(sum, "frames_per_second")) +
                (sum.contains("video_codec") && sum["video_codec"].is_string()
                     ? ", " + sum["video_codec"].get<std::string>()
                     : "");
    stages.push_back(s);
  }

  GVKIT_ASSIGN_OR_RETURN(nlohmann::json compare, read_if_present(work / "compare.stats.json"));
  if (!compare.is_null()) {
    const auto& sum = summary_of(compare);
    StageSummary s;
    s.stage = "compare";
    s.frames_in = s.frames_out = static_cast<int64_t>(number(sum, "frames", -1));
    s.figures = format(
        "decoded vs input: normal error mean %.2f / p95 %.2f / max %.1f deg, Hausdorff %.3f mm "
        "(outline %.3f mm)",
        number(sum, "normal_mean_deg"), number(sum, "normal_p95_deg"),
        number(sum, "normal_max_deg"), number(sum, "hausdorff_mm"),
        number(sum, "outline_hausdorff_mm"));
    stages.push_back(s);
  }

  // Times by stage name.
  if (run.contains("stages") && run["stages"].is_array()) {
    std::map<std::string, nlohmann::json> by_name;
    for (const auto& st : run["stages"])
      if (st.is_object() && st.contains("name") && st["name"].is_string())
        by_name[st["name"].get<std::string>()] = st;
    for (auto& s : stages)
      if (by_name.count(s.stage)) {
        s.seconds = number(by_name[s.stage], "seconds", -1);
        s.kept = by_name[s.stage].value("state", std::string()) == "kept";
      }
  }
  return stages;
}

std::string format_summary_table(const std::vector<StageSummary>& stages, int max_failures) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof(line), "%-12s %9s %9s  %s\n", "stage", "frames", "time", "figures");
  out += line;
  double total = 0;
  bool any_time = false;
  for (const auto& s : stages) {
    std::string frames = "-";
    if (s.frames_out >= 0 && s.frames_in >= 0)
      frames = std::to_string(s.frames_out) + "/" + std::to_string(s.frames_in);
    else if (s.frames_out >= 0)
      frames = std::to_string(s.frames_out);
    std::string time = "-";
    if (s.seconds >= 0) {
      time = format("%.1f s", s.seconds) + (s.kept ? "*" : "");
      total += s.seconds;
      any_time = true;
    }
    std::snprintf(line, sizeof(line), "%-12s %9s %9s  %s\n", s.stage.c_str(), frames.c_str(),
                  time.c_str(), s.figures.c_str());
    out += line;
  }
  if (any_time) {
    std::snprintf(line, sizeof(line), "%-12s %9s %9s\n", "total", "",
                  format("%.1f s", total).c_str());
    out += line;
  }
  for (const auto& s : stages)
    if (s.kept) {
      out += "* kept from an earlier run (its outputs were complete); the time is that run's\n";
      break;
    }
  for (const auto& s : stages) {
    if (s.failures.empty()) continue;
    out += s.stage + ": " + std::to_string(s.failures.size()) + " frame(s) failed:\n";
    for (size_t i = 0; i < s.failures.size() && static_cast<int>(i) < max_failures; ++i)
      out += "  " + s.failures[i] + "\n";
    if (static_cast<int>(s.failures.size()) > max_failures)
      out += "  ... (" + std::to_string(s.failures.size() - max_failures) +
             " more; see the stage's stats.json)\n";
  }
  return out;
}

}  // namespace gvkit::tools
