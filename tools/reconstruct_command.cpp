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
#include "fringe_input.hpp"
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
  std::string input, output, ground_truth;
  FringeInputArgs in;  // --pattern, --calibration and how a plain folder is read
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
  std::optional<StereoFolderInput> stereo;
  std::unique_ptr<capture::PatternSet> patterns;
  Calibration calibration;
  std::string calibration_note;
  capture::ReconstructOptions reconstruct_options = args.options;
  std::string depth_prior_from = args.depth_prior_given ? "--depth-prior" : "default";
  // Everything is read and checked before the output folder is touched: a bad input leaves an
  // earlier run's outputs as they were.
  if (fs::exists(input / "session.json")) {
    session = value_or_throw(capture::SessionReader::open(input));
    calibration = session->calibration();
    const std::string pattern_name =
        args.in.pattern.empty() ? session->info().pattern : args.in.pattern;
    patterns = value_or_throw(capture::create_pattern_set(pattern_name, args.pattern_options));
    if (!args.depth_prior_given && session->info().depth_prior_mm > 0) {
      reconstruct_options.depth_prior_mm = session->info().depth_prior_mm;
      depth_prior_from = "session";
    }
    if (!args.in.calibration.empty()) {
      CalibrationReadOptions read_options = value_or_throw(calibration_read_options(args.in));
      read_options.camera_size = {calibration.camera_width, calibration.camera_height};
      calibration =
          value_or_throw(read_calibration(std::vector<fs::path>(args.in.calibration.begin(),
                                                                args.in.calibration.end()),
                                          read_options))
              .calibration;
    }
  } else if (!stereo_subfolders(input).empty()) {
    stereo = value_or_throw(open_stereo_folder(input, args.in, args.pattern_options));
    patterns = std::move(stereo->patterns);
    calibration_note = "camera pair " + stereo->layout;
    logger().info("reconstruct: a camera pair ({}), {} frames of {} images each", stereo->layout,
                  stereo->left.frames.size(), patterns->image_count());
  } else {
    FringeFolderInput in = value_or_throw(open_fringe_folder(input, args.in, args.pattern_options));
    patterns = std::move(in.patterns);
    folder = std::move(in.folder);
    calibration = in.calibration;
    calibration_note = in.calibration_note;
    logger().info("reconstruct: {} frames of {} images in {}; calibration: {}",
                  folder->frames.size(), patterns->image_count(), input.string(), calibration_note);
  }
  if (!args.ground_truth.empty() && !fs::is_directory(args.ground_truth))
    throw CommandFailed(not_found(args.ground_truth + ": no such folder (--ground-truth)"));
  // One frame's scan: projector-camera triangulation, or matching between a camera pair.
  std::optional<capture::Reconstructor> reconstructor;
  std::optional<capture::StereoReconstructor> pair;
  if (stereo) {
    capture::StereoOptions stereo_options;
    stereo_options.min_depth_mm = reconstruct_options.min_depth_mm;
    stereo_options.max_depth_mm = reconstruct_options.max_depth_mm;
    if (!args.in.projector_size.empty())
      stereo_options.projector_width =
          value_or_throw(calibration_read_options(args.in)).projector_size.width;
    pair.emplace(
        value_or_throw(capture::StereoReconstructor::create(stereo->calibration, stereo_options)));
    if (!patterns->absolute())
      throw CommandFailed(invalid_argument(
          "pattern set " + patterns->name() +
          " is unwrapped spatially: its phase differs between the cameras by unknown whole "
          "periods; a camera pair needs an absolute pattern set (mf, het, gray, cgray)"));
  } else {
    reconstructor.emplace(
        value_or_throw(capture::Reconstructor::create(calibration, reconstruct_options)));
  }
  auto reconstruct_frame = [&](size_t i) -> Result<RangeScan> {
    if (stereo) {
      GVKIT_ASSIGN_OR_RETURN(FringeSet left, capture::read_fringe_frame(stereo->left, i));
      GVKIT_ASSIGN_OR_RETURN(FringeSet right, capture::read_fringe_frame(stereo->right, i));
      return pair->reconstruct(left, right, *patterns);
    }
    GVKIT_ASSIGN_OR_RETURN(FringeSet fringes, session ? session->read_frame(i)
                                                      : capture::read_fringe_frame(*folder, i));
    return reconstructor->reconstruct(fringes, *patterns);
  };
  throw_if_error(ensure_directory(output));

  const size_t count = session  ? session->frame_count()
                       : stereo ? stereo->left.frames.size()
                                : folder->frames.size();
  const nlohmann::json options = {{"pattern", patterns->name()},
                                  {"calibration", args.in.calibration},
                                  {"calibration_note", calibration_note},
                                  {"images", args.in.folder.include},
                                  {"exclude", args.in.folder.exclude},
                                  {"sliding", args.in.folder.sliding},
                                  {"ground_truth", args.ground_truth},
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
    Result<RangeScan> scan = reconstruct_frame(i);
    if (!scan) return fail(scan.status());
    const int64_t index = scan->index;
    Status s = write_range_scan_exr(frame_path(output, index, ".exr"), *scan);
    if (s && args.ply)
      s = write_mesh(frame_path(output, index, ".ply"), capture::range_scan_mesh(*scan));
    if (!s) return fail(s);
    std::optional<capture::ScanAccuracy> accuracy;
    std::optional<fs::path> gt_path;
    if (!args.ground_truth.empty())
      gt_path = frame_path(args.ground_truth, index, ".exr");
    else if (session)
      gt_path = session->ground_truth_path(index);
    if (gt_path) {
      Result<capture::GroundTruth> gt = capture::read_ground_truth_exr(*gt_path);
      if (!gt) return fail(gt.status());
      if (gt->xyz_mm.size() != scan->xyz_mm.size())
        return fail(invalid_argument(gt_path->string() + ": ground truth of another image size"));
      accuracy = capture::scan_accuracy(*scan, *gt);
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
  cmd->add_option("--pattern", args->in.pattern,
                  "Pattern set (default: the session's), a name or a SPEC.json file: " +
                      capture::pattern_set_help());
  cmd->add_option("--calibration", args->in.calibration,
                  "Calibration file(s), YAML/XML/JSON in the gvkit, SLStudio, procam "
                  "(scan3d-capture), OpenCV stereo_calib (intrinsics.yml,extrinsics.yml) or OpenCV "
                  "camera-sample layout")
      ->delimiter(',');
  cmd->add_option("--projector-size", args->in.projector_size,
                  "Projector resolution WxH, for calibration layouts that do not record it");
  cmd->add_option("--calibration-unit", args->in.calibration_unit,
                  "Length unit of the calibration's translation: mm, cm or m")
      ->capture_default_str();
  cmd->add_flag("--rescale-calibration", args->in.rescale_calibration,
                "Scale the camera intrinsics to the images when they have another resolution "
                "than the calibration but the same aspect ratio (binned or resized images)");
  cmd->add_option("--images", args->in.folder.include,
                  "Plain folder: only image files whose names match this glob (e.g. 'cam0_*')");
  cmd->add_option("--exclude", args->in.folder.exclude,
                  "Plain folder: leave out image files whose names match this glob");
  cmd->add_flag("--sliding", args->in.folder.sliding,
                "Plain folder: a continuous sequence; frame i is images i..i+N-1 (a sliding "
                "window, image j filling pattern slot j mod N)");
  cmd->add_option("--ground-truth", args->ground_truth,
                  "Folder of ground-truth EXRs (frame_NNNNNN.exr, as gvkit synth writes in gt/) "
                  "to measure depth errors against");
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
