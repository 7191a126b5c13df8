// gvkit reconstruct INPUT -o SCANS: fringe images -> RangeScan EXRs (frame_NNNNNN.exr), optional
// PLY meshes, and stats.json (valid share; depth error against ground truth when present).
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gvkit/capture/fringe_folder.hpp"
#include "gvkit/capture/ground_truth.hpp"
#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/range_scan_mesh.hpp"
#include "gvkit/capture/reconstructor.hpp"
#include "gvkit/capture/scan_accuracy.hpp"
#include "gvkit/capture/session_reader.hpp"
#include "gvkit/core/calibration_io.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/log.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "gvkit/core/progress.hpp"
#include "tool_support.hpp"

namespace gvkit::tools {
namespace {
namespace fs = std::filesystem;

struct ReconstructArgs {
  std::string input, output, pattern, calibration;
  bool ply = false, quiet = false, resume = false;
  bool depth_prior_given = false;  // --depth-prior on the command line (else the session's)
  capture::ReconstructOptions options;
  capture::PatternSetOptions pattern_options;
};

// The stats.json entry of one reconstructed frame.
nlohmann::json frame_entry(int64_t index, const RangeScan& scan,
                           const std::optional<capture::ScanAccuracy>& accuracy) {
  nlohmann::json j = {{"index", index}, {"valid_share", scan.valid_fraction()}};
  if (accuracy) {
    const auto& a = *accuracy;
    j["rms_depth_error_mm"] = a.rms_mm;
    j["max_depth_error_mm"] = a.max_mm;
    j["median_depth_error_mm"] = a.p50_mm;
    j["p99_depth_error_mm"] = a.p99_mm;
    j["face_interior_rms_mm"] = a.face_interior_rms_mm;
    j["face_interior_max_mm"] = a.face_interior_max_mm;
    j["face_interior_valid_share"] = a.face_interior_valid_share;
  }
  return j;
}

void run(const ReconstructArgs& args) {
  const fs::path input = args.input, output = args.output;
  std::optional<capture::SessionReader> session;
  std::optional<capture::FringeFolder> folder;
  Calibration calibration;
  std::string pattern_name = args.pattern;
  capture::ReconstructOptions reconstruct_options = args.options;
  std::string depth_prior_from = args.depth_prior_given ? "--depth-prior" : "default";
  if (fs::exists(input / "session.json")) {
    session = value_or_throw(capture::SessionReader::open(input));
    calibration = session->calibration();
    if (pattern_name.empty()) pattern_name = session->info().pattern;
    if (!args.depth_prior_given && session->info().depth_prior_mm > 0) {
      reconstruct_options.depth_prior_mm = session->info().depth_prior_mm;
      depth_prior_from = "session";
    }
    if (!args.calibration.empty())
      calibration = value_or_throw(read_calibration(args.calibration)).calibration;
  } else {
    if (pattern_name.empty() || args.calibration.empty())
      throw CommandFailed(
          invalid_argument(input.string() +
                           ": not a session (no session.json); a folder of fringe images needs "
                           "--pattern and --calibration"));
    calibration = value_or_throw(read_calibration(args.calibration)).calibration;
  }
  auto patterns = value_or_throw(capture::create_pattern_set(pattern_name, args.pattern_options));
  if (!session)
    folder = value_or_throw(capture::list_fringe_folder(input, patterns->image_count()));
  const capture::Reconstructor reconstructor =
      value_or_throw(capture::Reconstructor::create(calibration, reconstruct_options));
  throw_if_error(ensure_directory(output));

  const size_t count = session ? session->frame_count() : folder->frames.size();
  const nlohmann::json options = {{"pattern", patterns->name()},
                                  {"calibration", args.calibration},
                                  {"depth_prior_mm", reconstruct_options.depth_prior_mm},
                                  {"depth_prior_from", depth_prior_from},
                                  {"min_modulation", args.pattern_options.min_modulation},
                                  {"saturation_level", args.pattern_options.saturation_level},
                                  {"unwrap_tolerance", args.pattern_options.unwrap_tolerance},
                                  {"reference", args.options.reference},
                                  {"ply", args.ply}};
  FrameStatsFile stats_file(
      output, {{"command", "reconstruct"}, {"input", input.string()}, {"options", options}},
      args.resume);
  if (!stats_file.resume_note().empty()) logger().info("{}", stats_file.resume_note());
  std::vector<nlohmann::json> entries(count);
  std::atomic<int64_t> kept{0};
  Progress progress("reconstruct", static_cast<int64_t>(count), !args.quiet);
  std::mutex error_mutex;
  std::optional<Status> first_error;
  tbb::parallel_for(size_t{0}, count, [&](size_t i) {
    auto fail = [&](const Status& s) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!first_error) first_error = s;
    };
    // A frame finished by an earlier run (its entry recorded, its files complete) is kept.
    const int64_t listed = session ? session->info().frames[i].index : static_cast<int64_t>(i);
    if (auto previous = stats_file.previous(listed)) {
      std::vector<fs::path> outputs = {frame_path(output, listed, ".exr")};
      if (args.ply) outputs.push_back(frame_path(output, listed, ".ply"));
      if (all_exist(outputs)) {
        entries[i] = *previous;
        if (Status s = stats_file.record(listed, *previous); !s) return fail(s);
        ++kept;
        progress.advance();
        return;
      }
    }
    Result<FringeSet> fringes =
        session ? session->read_frame(i) : capture::read_fringe_frame(*folder, i);
    if (!fringes) return fail(fringes.status());
    Result<RangeScan> scan = reconstructor.reconstruct(*fringes, *patterns);
    if (!scan) return fail(scan.status());
    const int64_t index = fringes->index;
    Status s = write_range_scan_exr(frame_path(output, index, ".exr"), *scan);
    if (s && args.ply)
      s = write_mesh(frame_path(output, index, ".ply"), capture::range_scan_mesh(*scan));
    if (!s) return fail(s);
    std::optional<capture::ScanAccuracy> accuracy;
    if (session) {
      if (auto gt_path = session->ground_truth_path(index)) {
        Result<capture::GroundTruth> gt = capture::read_ground_truth_exr(*gt_path);
        if (!gt) return fail(gt.status());
        accuracy = capture::scan_accuracy(*scan, *gt);
      }
    }
    entries[i] = frame_entry(index, *scan, accuracy);
    if (Status r = stats_file.record(index, entries[i]); !r) return fail(r);
    progress.advance();
  });
  progress.finish();
  if (first_error) throw CommandFailed(*first_error);
  if (kept > 0)
    logger().info("reconstruct: {} of {} frames were already done in {}; kept, not recomputed",
                  kept.load(), count, output.string());

  nlohmann::json frames = nlohmann::json::array();
  double valid_sum = 0, rms2_sum = 0, max_all = 0, interior2_sum = 0, interior_share_sum = 0;
  int with_gt = 0;
  for (const nlohmann::json& j : entries) {
    valid_sum += j.value("valid_share", 0.0);
    if (j.contains("rms_depth_error_mm")) {
      const double rms = j["rms_depth_error_mm"], interior = j["face_interior_rms_mm"];
      rms2_sum += rms * rms;
      interior2_sum += interior * interior;
      interior_share_sum += j["face_interior_valid_share"].get<double>();
      max_all = std::max(max_all, j["max_depth_error_mm"].get<double>());
      ++with_gt;
    }
    frames.push_back(j);
  }
  nlohmann::json summary = {{"frames", count},
                            {"kept_from_earlier_run", kept.load()},
                            {"mean_valid_share", count ? valid_sum / count : 0.0}};
  if (with_gt) {
    summary["rms_depth_error_mm"] = std::sqrt(rms2_sum / with_gt);
    summary["max_depth_error_mm"] = max_all;
    summary["face_interior_rms_mm"] = std::sqrt(interior2_sum / with_gt);
    summary["face_interior_valid_share"] = interior_share_sum / with_gt;
  }
  throw_if_error(stats_file.finish(summary, frames));
  std::printf("reconstructed %zu frames into %s: mean valid share %.3f", count,
              output.string().c_str(), count ? valid_sum / count : 0.0);
  if (with_gt)
    std::printf(", RMS depth error %.4f mm (face interior %.4f mm, valid %.4f)",
                summary["rms_depth_error_mm"].get<double>(),
                summary["face_interior_rms_mm"].get<double>(),
                summary["face_interior_valid_share"].get<double>());
  std::printf("\n");
}

}  // namespace

void add_reconstruct_command(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("reconstruct",
                         "Fringe images (a session, or a folder + --pattern + --calibration) -> "
                         "range scans (frame_NNNNNN.exr) and stats.json");
  auto args = std::make_shared<ReconstructArgs>();
  cmd->add_option("input", args->input, "Session folder, or a folder of fringe images")->required();
  cmd->add_option("-o,--output", args->output, "Output folder for the scans")->required();
  cmd->add_option("--pattern", args->pattern,
                  "Pattern set (default: the session's): " + capture::pattern_set_help());
  cmd->add_option("--calibration", args->calibration,
                  "Calibration file (gvkit YAML/JSON/XML or SLStudio calibration.xml)");
  cmd->add_flag("--ply", args->ply, "Also write frame_NNNNNN.ply meshes with texture");
  cmd->add_option("--depth-prior", args->options.depth_prior_mm,
                  "Expected depth (mm) resolving spatially unwrapped regions (default: the "
                  "session's depth_prior_mm when it records one, else 650)")
      ->each([args](const std::string&) { args->depth_prior_given = true; });
  cmd->add_option("--min-depth", args->options.min_depth_mm, "Nearest valid depth (mm)")
      ->capture_default_str();
  cmd->add_option("--max-depth", args->options.max_depth_mm, "Farthest valid depth (mm)")
      ->capture_default_str();
  cmd->add_option("--min-modulation", args->pattern_options.min_modulation,
                  "Fringe modulation below which a pixel is invalid (fraction of the range)")
      ->capture_default_str();
  cmd->add_option("--unwrap-tolerance", args->pattern_options.unwrap_tolerance,
                  "Temporal unwrapping tolerance (periods)")
      ->capture_default_str();
  cmd->add_flag("--reference", args->options.reference,
                "Use the plain reference triangulation (slow)");
  cmd->add_flag("--no-progress", args->quiet, "Do not show progress");
  cmd->add_flag("--resume", args->resume,
                "Keep the frames an earlier run with the same options finished in the output "
                "folder (listed in its stats.json, files present); compute only the others");
  cmd->callback([args] {
    args->pattern_options.reference = args->options.reference;
    run(*args);
  });
}

}  // namespace gvkit::tools
