// gvkit run INPUT -o WORK: the whole chain on a session folder (or the synthetic source) in one
// command: [synth ->] reconstruct -> facemap clean -> facemap map -> encode -> decode [-> render
// -> compare].
// Each stage runs as its own gvkit subcommand; its outputs stay in WORK (session/, scans/, faces/,
// gv/, face.gvid, decoded/, face.mp4, compare.png / .mp4) and its console output in
// WORK/logs/STAGE.log. Resumable:
// a stage whose outputs are complete is skipped, and the per-frame stages keep the frames an
// earlier run finished (--resume). WORK/run.json records each stage's command, state and time;
// the result table (see work_summary.hpp) ends the run.
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gvkit/codec/encoder_options.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "tool_support.hpp"
#include "work_summary.hpp"

namespace gvkit::tools {
namespace {
namespace fs = std::filesystem;

struct RunArgs {
  std::string input, work, pattern;
  std::vector<std::string> calibration;
  // Passed to reconstruct for a plain folder of fringe images ("" / false = not given).
  std::string projector_size, calibration_unit, images, exclude, ground_truth;
  bool rescale_calibration = false, sliding = false;
  int frames = 30;
  std::string size = "512x512", map_size = "320x320", preset = "slow", expressions = "mix",
              exr_compression = "zip";
  int qp = codec::EncoderOptions().qp;
  double depth_prior_mm = 0;  // 0: reconstruct's default (the session's, else 650 mm)
  bool render = false, restart = false;
};

struct Stage {
  std::string name;
  std::vector<std::string> args;  // after "gvkit"
  std::function<bool()> complete;
};

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Runs `gvkit ARGS` (this program) with stdout and stderr shown and copied to log; the exit code.
int run_child(const std::vector<std::string>& args, const fs::path& log) {
  std::string command = shell_quote(fs::read_symlink("/proc/self/exe").string());
  for (const auto& a : args) command += " " + shell_quote(a);
  std::FILE* out = std::fopen(log.c_str(), "w");
  std::FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) {
    if (out) std::fclose(out);
    return 127;
  }
  char buffer[4096];
  while (std::fgets(buffer, sizeof(buffer), pipe)) {
    std::fputs(buffer, stdout);
    std::fflush(stdout);
    if (out) std::fputs(buffer, out);
  }
  const int status = pclose(pipe);
  if (out) std::fclose(out);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// A per-frame stage is complete when its stats.json says so and every frame it lists as done
// still has its files.
bool frames_complete(const fs::path& dir, const std::vector<std::string>& suffixes) {
  auto stats = read_json(dir / "stats.json");
  if (!stats.is_ok() || !stats->is_object() || stats->value("complete", false) != true ||
      !stats->contains("frames"))
    return false;
  for (const auto& f : (*stats)["frames"]) {
    if (!f.is_object() || f.contains("error") || f.value("ok", true) == false) continue;
    std::vector<fs::path> files;
    for (const auto& s : suffixes) files.push_back(frame_path(dir, f.value("index", -1), s));
    if (!all_exist(files)) return false;
  }
  return true;
}

// True when the stats file exists and its summary counts no failed frame under `failed_key`.
bool finished_without_failures(const fs::path& stats_path, const char* failed_key) {
  auto stats = read_json(stats_path);
  if (!stats.is_ok() || !stats->contains("summary") || !(*stats)["summary"].is_object())
    return false;
  const auto& failed = (*stats)["summary"].value(failed_key, nlohmann::json(0));
  return failed.is_number() && failed.get<double>() == 0;
}

// True when dir holds the synthetic session these options ask for, every frame written.
bool synthetic_session_complete(const fs::path& dir, const RunArgs& a) {
  auto info = read_json(dir / "session.json");
  if (!info.is_ok() || !info->contains("frames") || !(*info)["frames"].is_array()) return false;
  const auto size = parse_size(a.size);
  const nlohmann::json source = info->value("source", nlohmann::json::object());
  return static_cast<int>((*info)["frames"].size()) == a.frames && size.is_ok() &&
         info->value("image_size", nlohmann::json()) ==
             nlohmann::json({size->first, size->second}) &&
         source.is_object() && source.value("expressions", std::string()) == a.expressions;
}

void run(const RunArgs& a) {
  if (a.frames < 1) throw CommandFailed(invalid_argument("--frames must be >= 1"));
  if (!(a.depth_prior_mm >= 0))
    throw CommandFailed(invalid_argument("--depth-prior must be a depth in mm"));
  throw_if_error(parse_size(a.size).status().with_context("--size"));
  throw_if_error(parse_size(a.map_size).status().with_context("--map-size"));
  codec::EncoderOptions encoder;
  encoder.qp = a.qp;
  throw_if_error(encoder.check());
  throw_if_error(codec::parse_preset(a.preset).status());
  throw_if_error(exr_compression_option(a.exr_compression).status());
  const fs::path work = a.work;
  const bool synthetic = a.input == "synthetic";
  std::error_code ec;
  if (!synthetic && !fs::is_directory(a.input, ec))
    throw CommandFailed(not_found(a.input + ": no such folder (a session folder, a folder of "
                                            "fringe images, or 'synthetic')"));
  if (a.restart) fs::remove_all(work, ec);
  throw_if_error(ensure_directory(work / "logs"));
  const fs::path session = synthetic ? work / "session" : fs::path(a.input);

  std::vector<Stage> stages;
  if (synthetic) {
    stages.push_back({"synth",
                      {"synth", "-o", session.string(), "--frames", std::to_string(a.frames),
                       "--size", a.size, "--expressions", a.expressions, "--no-progress"},
                      [&] { return synthetic_session_complete(session, a); }});
  }
  std::vector<std::string> reconstruct = {"reconstruct", session.string(), "-o",
                                          (work / "scans").string(), "--resume"};
  if (!a.pattern.empty()) reconstruct.insert(reconstruct.end(), {"--pattern", a.pattern});
  for (const std::string& file : a.calibration)
    reconstruct.insert(reconstruct.end(), {"--calibration", file});
  for (auto [flag, value] :
       {std::pair{"--projector-size", &a.projector_size},
        std::pair{"--calibration-unit", &a.calibration_unit}, std::pair{"--images", &a.images},
        std::pair{"--exclude", &a.exclude}, std::pair{"--ground-truth", &a.ground_truth}})
    if (!value->empty()) reconstruct.insert(reconstruct.end(), {flag, *value});
  if (a.rescale_calibration) reconstruct.push_back("--rescale-calibration");
  if (a.sliding) reconstruct.push_back("--sliding");
  if (a.depth_prior_mm > 0) {
    char text[32];
    std::snprintf(text, sizeof text, "%.10g", a.depth_prior_mm);
    reconstruct.insert(reconstruct.end(), {"--depth-prior", text});
  }
  stages.push_back(
      {"reconstruct", reconstruct, [&] { return frames_complete(work / "scans", {".exr"}); }});
  stages.push_back(
      {"clean",
       {"facemap", "clean", (work / "scans").string(), "-o", (work / "faces").string(), "--resume"},
       [&] {
         return frames_complete(work / "faces", {".ply", ".landmarks.json"});
       }});
  stages.push_back(
      {"map",
       {"facemap", "map", (work / "faces").string(), "-o", (work / "gv").string(), "--size",
        a.map_size, "--png", "--resume", "--exr-compression", a.exr_compression},
       [&] {
         return frames_complete(work / "gv", {".exr", ".png"});
       }});
  const std::string gvid = (work / "face.gvid").string();
  stages.push_back({"encode",
                    {"encode", (work / "gv").string(), "-o", gvid, "--qp", std::to_string(a.qp),
                     "--preset", a.preset},
                    [&] { return fs::exists(gvid + ".stats.json") && fs::exists(gvid); }});
  stages.push_back(
      {"decode",
       {"decode", gvid, "-o", (work / "decoded").string(), "--exr-compression", a.exr_compression},
       [&] {
         return finished_without_failures(work / "decoded" / "stats.json", "failed_frames");
       }});
  if (a.render) {
#ifdef GVKIT_WITH_PLAYER
    stages.push_back(
        {"render",
         {"render", (work / "decoded").string(), "-o", (work / "face.mp4").string(),
          "--contact-sheet", (work / "contact.png").string()},
         [&] { return finished_without_failures(work / "face.stats.json", "failed"); }});
    // The decoded face beside its input, with the normal-error heat map (issue 30).
    stages.push_back(
        {"compare",
         {"compare", (work / "gv").string(), (work / "decoded").string(), "-o",
          (work / "compare.mp4").string(), "--contact-sheet", (work / "compare.png").string()},
         [&] { return fs::exists(work / "compare.stats.json"); }});
#else
    throw CommandFailed(unsupported("--render: this gvkit was built without the player"));
#endif
  }

  // The earlier run's record: times of the stages that are kept.
  nlohmann::json earlier = nlohmann::json::object();
  if (auto old = read_json(work / "run.json"); old.is_ok() && old->contains("stages"))
    for (const auto& s : (*old)["stages"])
      if (s.is_object() && s.contains("name")) earlier[s["name"].get<std::string>()] = s;
  nlohmann::json record = {{"input", a.input},
                           {"session", session.string()},
                           {"work", work.string()},
                           {"stages", nlohmann::json::array()},
                           {"complete", false}};
  bool upstream_ran = false;
  for (size_t i = 0; i < stages.size(); ++i) {
    const Stage& stage = stages[i];
    std::string shown = "gvkit";
    for (const auto& arg : stage.args) shown += " " + arg;
    nlohmann::json entry = {{"name", stage.name}, {"command", shown}};
    if (!upstream_ran && stage.complete()) {
      std::printf("== [%zu/%zu] %s: outputs complete from an earlier run; skipped\n", i + 1,
                  stages.size(), stage.name.c_str());
      entry["state"] = "kept";
      entry["seconds"] =
          earlier.contains(stage.name) ? earlier[stage.name].value("seconds", 0.0) : 0.0;
      record["stages"].push_back(entry);
      continue;
    }
    if (stage.name == "synth") {
      // A new session: nothing made from an earlier one may be kept.
      for (const char* stale : {"session", "scans", "faces", "gv", "decoded", "face.gvid",
                                "face.gvid.stats.json", "face.mp4", "face.stats.json",
                                "contact.png", "compare.mp4", "compare.png", "compare.stats.json"})
        fs::remove_all(work / stale, ec);
    }
    std::printf("== [%zu/%zu] %s: %s\n", i + 1, stages.size(), stage.name.c_str(), shown.c_str());
    std::fflush(stdout);
    const fs::path log = work / "logs" / (stage.name + ".log");
    const auto start = std::chrono::steady_clock::now();
    const int code = run_child(stage.args, log);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    entry["seconds"] = seconds;
    entry["state"] = code == 0 ? "ran" : "failed";
    entry["exit_code"] = code;
    record["stages"].push_back(entry);
    throw_if_error(write_json(work / "run.json", record));
    if (code != 0) {
      // The table of what was made so far, then the failure.
      if (auto summary = summarize_work_folder(work); summary.is_ok())
        std::printf("\n%s", format_summary_table(*summary).c_str());
      std::fflush(stdout);
      throw CommandFailed(failed_precondition(
          "stage '" + stage.name + "' failed (exit " + std::to_string(code) + "); its log is " +
          log.string() + "; run the same command again to resume"));
    }
    std::printf("== [%zu/%zu] %s: done in %.1f s\n", i + 1, stages.size(), stage.name.c_str(),
                seconds);
    upstream_ran = true;
  }
  record["complete"] = true;
  throw_if_error(write_json(work / "run.json", record));
  const auto summary = value_or_throw(summarize_work_folder(work));
  std::printf("\n%s: %s\n%s", work.string().c_str(), gvid.c_str(),
              format_summary_table(summary).c_str());
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto a = std::make_shared<RunArgs>();
  auto* cmd = app.add_subcommand(
      "run",
      "The whole chain: a session folder (or 'synthetic') -> WORK/face.gvid, every stage's "
      "outputs kept in WORK, resumable, ending with the result table");
  cmd->add_option("input", a->input,
                  "Session folder (session.json), a folder of fringe images (with --pattern and "
                  "--calibration), or 'synthetic' (the ICT face rendered into WORK/session)")
      ->required();
  cmd->add_option("-o,--output", a->work, "Work folder (created; kept between runs)")->required();
  cmd->add_option("--frames", a->frames, "Frames of the synthetic source")->capture_default_str();
  cmd->add_option("--size", a->size, "Camera image size WxH of the synthetic source")
      ->capture_default_str();
  cmd->add_option("--expressions", a->expressions,
                  "Expression track of the synthetic source (synth --expressions)")
      ->capture_default_str();
  cmd->add_option("--pattern", a->pattern,
                  "Pattern set of a folder of fringe images: a name or a SPEC.json (reconstruct "
                  "--pattern)");
  cmd->add_option("--calibration", a->calibration,
                  "Calibration file(s) of a folder of fringe images (reconstruct --calibration)")
      ->delimiter(',');
  cmd->add_option("--projector-size", a->projector_size,
                  "Projector WxH where the calibration lacks it (reconstruct --projector-size)");
  cmd->add_option("--calibration-unit", a->calibration_unit,
                  "Calibration length unit mm, cm or m (reconstruct --calibration-unit)");
  cmd->add_flag("--rescale-calibration", a->rescale_calibration,
                "Fit the camera intrinsics to images of another resolution, same aspect "
                "(reconstruct --rescale-calibration)");
  cmd->add_option("--images", a->images, "Only images matching this glob (reconstruct --images)");
  cmd->add_option("--exclude", a->exclude, "Leave out images matching this glob");
  cmd->add_flag("--sliding", a->sliding,
                "A continuous sequence read as sliding windows (reconstruct --sliding)");
  cmd->add_option("--ground-truth", a->ground_truth,
                  "Reference EXRs to measure the scans against (reconstruct --ground-truth)");
  cmd->add_option("--depth-prior", a->depth_prior_mm,
                  "Expected face depth (mm) for spatially unwrapped pattern sets (reconstruct "
                  "--depth-prior; default: the session's, else 650)");
  cmd->add_option("--map-size", a->map_size, "Geometry image size WxH (facemap map --size)")
      ->capture_default_str();
  cmd->add_option("--qp", a->qp, "Encoder quantization parameter (encode --qp)")
      ->capture_default_str();
  cmd->add_option("--preset", a->preset, "Encoder preset: fast or slow")->capture_default_str();
  cmd->add_option("--exr-compression", a->exr_compression,
                  "Compression of the geometry images of WORK/gv and WORK/decoded (facemap map "
                  "and decode --exr-compression): zip, rle or none, all lossless")
      ->capture_default_str();
  cmd->add_flag("--render", a->render,
                "Also render the decoded video offscreen to WORK/face.mp4 and WORK/contact.png, "
                "and it beside the input with a normal-error heat map to WORK/compare.mp4 and "
                "WORK/compare.png (gvkit compare)");
  cmd->add_flag("--restart", a->restart, "Delete WORK first (nothing is kept)");
  cmd->callback([a] { run(*a); });
}

}  // namespace gvkit::tools
