// gvkit facemap clean SCANS -o FACES: range scans (frame_NNNNNN.exr) or meshes
// (frame_NNNNNN.ply/.obj, or one mesh file of any name) -> per frame the 4-boundary face mesh
// (frame_NNNNNN.ply) and its landmarks (frame_NNNNNN.landmarks.json), plus stats.json. Frames
// run in parallel; a frame that fails is reported and skipped.
//
// Meshes are read as the file has them (triangle soup) and repaired (mesh_from_soup): what was
// repaired is counted per frame in stats.json; a mesh that cannot be one face surface is
// rejected with the reason. Their landmarks: a file per frame (--landmarks FOLDER, or beside the
// mesh), --landmarks FILE for the first (or only) frame, else dlib on renders of the mesh (its
// texture image when it has one). With --same-vertices the first frame is cleaned and carried to
// the others (meshes read through OpenMesh: a registered sequence is not a raw scan).
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "clean_inputs.hpp"
#include "command.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/face_landmarks_io.hpp"
#include "gvkit/core/file_extension.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/landmark_points_io.hpp"
#include "gvkit/core/log.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "gvkit/core/progress.hpp"
#include "gvkit/core/triangle_soup.hpp"
#include "gvkit/facemap/face_cleaning.hpp"
#include "gvkit/facemap/face_transfer.hpp"
#include "gvkit/facemap/landmark_detector.hpp"
#include "gvkit/facemap/landmark_tracker.hpp"
#include "gvkit/facemap/mesh_from_soup.hpp"
#include "gvkit/facemap/mesh_landmarks.hpp"
#include "tool_support.hpp"

namespace gvkit::tools {
namespace {
namespace fs = std::filesystem;
using facemap::CleanOptions;

struct CleanArgs {
  fs::path input, output, landmarks, model = facemap::kDefaultShapePredictorPath;
  CleanOptions options;
  std::string mouth = "inner";
  std::string units;  // mm, cm, m; empty: not given
  double scale = 0;   // mm per mesh unit; 0: not given
  bool detect = true;
  bool one_piece = false;
  double min_piece_share = 0.5;
  int threads = 0;
  bool resume = false;
  bool same_vertices = false;
};

enum class InputKind { kScans, kMeshes };

struct Frame {
  int64_t index = 0;
  fs::path path;
  std::optional<FaceLandmarks> landmarks;  // tracked (scans with --landmarks)
  std::optional<fs::path> landmark_file;   // meshes: where the landmarks come from (else detect)
  Status status;
  facemap::CleanStats stats;
  std::optional<facemap::TransferStats> transfer;  // --same-vertices, frames after the first
  nlohmann::json mesh_input;                       // meshes: what was read, repaired, found
};

// The frames of the input: a folder of frame_NNNNNN.exr, else .ply, else .obj; or one file (its
// index from a frame_NNNNNN name, else 0).
std::vector<FrameFile> input_frames(const fs::path& input, InputKind* kind) {
  std::error_code ec;
  if (fs::is_regular_file(input, ec)) {
    const std::string ext = lower_extension(input);
    if (ext == ".exr")
      *kind = InputKind::kScans;
    else if (ext == ".ply" || ext == ".obj")
      *kind = InputKind::kMeshes;
    else
      throw CommandFailed(
          unsupported(input.string() + ": not a range scan (.exr) or a mesh (.ply, .obj)"));
    int64_t index = 0;
    const std::string stem = input.stem().string();
    if (stem.size() == 12 && stem.rfind("frame_", 0) == 0 &&
        stem.find_first_not_of("0123456789", 6) == std::string::npos)
      index = std::stoll(stem.substr(6));
    return {FrameFile{index, input}};
  }
  *kind = InputKind::kScans;
  std::vector<FrameFile> files = value_or_throw(list_frame_files(input, ".exr"));
  if (files.empty()) {
    *kind = InputKind::kMeshes;
    files = value_or_throw(list_frame_files(input, ".ply"));
    if (files.empty()) files = value_or_throw(list_frame_files(input, ".obj"));
  }
  if (files.empty())
    throw CommandFailed(not_found(input.string() + ": no frame_NNNNNN.exr, .ply or .obj files"));
  return files;
}

// The dlib detector, loaded once (about a second) by the first frame that needs it.
class LazyDetector {
 public:
  explicit LazyDetector(fs::path model) : model_(std::move(model)) {}
  Result<const facemap::LandmarkDetector*> get() {
    std::call_once(once_, [&] {
      facemap::LandmarkDetectorOptions options;
      options.model_path = model_;
      auto created = facemap::LandmarkDetector::create(options);
      if (created.is_ok())
        detector_ = std::make_unique<facemap::LandmarkDetector>(std::move(created).value());
      else
        status_ = created.status();
    });
    if (!detector_) return status_;
    return detector_.get();
  }

 private:
  fs::path model_;
  std::once_flag once_;
  std::unique_ptr<facemap::LandmarkDetector> detector_;
  Status status_;
};

nlohmann::json options_json(const CleanArgs& a) {
  const CleanOptions& o = a.options;
  return {{"radius_mm", o.mask.radius_mm},
          {"radius_factor", o.mask.radius_factor},
          {"mouth_contour", a.mouth},
          {"eye_margin_mm", o.mask.eye_margin_mm},
          {"mouth_margin_mm", o.mask.mouth_margin_mm},
          {"max_edge_factor", o.scan.max_edge_factor},
          {"max_hole_edges", o.holes.max_hole_edges},
          {"landmark_max_gap_px", o.landmark_max_gap_px},
          {"landmark_max_snap_mm", o.landmark_max_snap_mm},
          {"cut_feature_interiors", o.cut_feature_interiors},
          {"fill_feature_holes", o.fill_feature_holes},
          {"landmarks", a.landmarks.string()},
          {"detect_landmarks", a.detect},
          {"mm_per_unit", a.scale},
          {"one_piece", a.one_piece},
          {"min_piece_share", a.min_piece_share},
          {"same_vertices", a.same_vertices},
          {"threads", a.threads}};
}

nlohmann::json frame_json(const Frame& f) {
  nlohmann::json j = {
      {"index", f.index}, {"input", f.path.filename().string()}, {"ok", f.status.is_ok()}};
  std::vector<fs::path> inputs = {f.path};
  if (f.landmark_file) inputs.push_back(*f.landmark_file);
  j["inputs"] = input_fingerprint(inputs);
  if (!f.mesh_input.is_null()) j["mesh_input"] = f.mesh_input;
  if (!f.status.is_ok()) {
    j["error"] = f.status.message();
    return j;
  }
  const auto& s = f.stats;
  j["input_vertices"] = s.input_vertices;
  j["input_faces"] = s.input_faces;
  j["repair"] = s.repair;
  j["feature_pixels_removed"] = s.feature_pixels_removed;
  j["landmarks_snapped"] = {{"to_mesh_pixels", s.landmarks_snapped_px},
                            {"max_px", s.landmark_max_snap_px},
                            {"to_surface", s.landmarks_snapped_mm},
                            {"max_mm", s.landmark_max_snap_mm}};
  j["holes_filled"] = s.holes_filled;
  j["stray_holes_filled"] = s.stray_holes_filled;
  j["pinch_faces_removed"] = s.pinch_faces_removed;
  j["feature_holes_open"] = s.feature_holes_open;
  j["vertices_added"] = s.vertices_added;
  j["output_vertices"] = s.output_vertices;
  j["output_faces"] = s.output_faces;
  j["radius_mm"] = s.radius_mm;
  j["cropped_vertices"] = s.cropped_vertices;
  if (f.transfer)
    j["transferred_from_first_frame"] = {{"off_surface_vertices", f.transfer->off_surface_vertices},
                                         {"max_offset_mm", f.transfer->max_offset_mm}};
  const auto& m = s.mask_timing;
  j["ms"] = {{"mesh", s.mesh_ms},
             {"fill", s.fill_ms},
             {"mask", s.mask_ms},
             {"mask_steps",
              {{"crop", m.crop_ms},
               {"factor", m.factor_ms},
               {"regions", m.regions_ms},
               {"distances", m.distances_ms},
               {"clip", m.clip_ms},
               {"check", m.check_ms}}},
             {"total", s.total_ms}};
  return j;
}

// Landmarks of a mesh frame: its landmark file (points in the mesh file's units, or pixels of
// its texture image), else dlib on renders of the mesh. `how` receives where they came from.
Result<FaceLandmarks> mesh_frame_landmarks(const Frame& frame, const Mesh& mesh,
                                           const facemap::MeshTexture& texture, double scale,
                                           bool detect, LazyDetector* detector,
                                           nlohmann::json* how) {
  const std::string name = frame.path.filename().string();
  if (frame.landmark_file) {
    const fs::path& file = *frame.landmark_file;
    GVKIT_ASSIGN_OR_RETURN(const LandmarkPoints points, read_landmark_points(file, 3));
    *how = {{"source", "file"},
            {"file", file.filename().string()},
            {"points", points.file_count},
            {"dims", points.dims}};
    return facemap::landmarks_on_mesh(points, mesh, texture, scale, file.string());
  }
  if (!detect)
    return not_found(name + ": no landmark file (--landmarks FOLDER, or " +
                     frame.path.stem().string() +
                     ".landmarks.json beside it) and detection is off (--no-detect)");
  GVKIT_ASSIGN_OR_RETURN(const facemap::LandmarkDetector* dlib, detector->get());
  GVKIT_ASSIGN_OR_RETURN(facemap::MeshLandmarks found,
                         facemap::detect_mesh_landmarks(mesh, *dlib, name, {}, &texture));
  const char* render = found.render.textured   ? "texture"
                       : found.render.coloured ? "vertex colours"
                                               : "shading";
  *how = {{"source", "detected"},
          {"render", render},
          {"view", found.view_name},
          {"roll_deg", found.roll_deg},
          {"renders_tried", found.views_tried},
          {"moved_onto_surface", found.gap_filled},
          {"moved_out_of_cavities", found.cavity_moved}};
  return std::move(found.landmarks);
}

void run_clean(const CleanArgs& args) {
  CleanOptions options = args.options;
  if (args.mouth == "inner")
    options.mask.mouth_contour = facemap::MouthContour::kInner;
  else if (args.mouth == "outer")
    options.mask.mouth_contour = facemap::MouthContour::kOuter;
  else
    throw CommandFailed(invalid_argument("--mouth must be inner or outer, got " + args.mouth));
  throw_if_error(options.check());
  if (args.threads < 0) throw CommandFailed(invalid_argument("--threads must be >= 0"));
  if (!(args.min_piece_share >= 0 && args.min_piece_share <= 1))
    throw CommandFailed(invalid_argument("--min-piece-share must be in [0, 1]"));
  const double scale = value_or_throw(mesh_scale(args.units, args.scale));
  const bool units_given = !args.units.empty() || args.scale != 0;

  InputKind kind = InputKind::kScans;
  const std::vector<FrameFile> files = input_frames(args.input, &kind);
  std::error_code ec;
  const bool landmarks_folder = !args.landmarks.empty() && fs::is_directory(args.landmarks, ec);
  if (!args.landmarks.empty() && !landmarks_folder && !fs::is_regular_file(args.landmarks, ec))
    throw CommandFailed(not_found(args.landmarks.string() + ": no such file or folder"));
  if (kind == InputKind::kScans && units_given)
    throw CommandFailed(invalid_argument("--units/--scale are for meshes; range scans are in mm"));
  if (kind == InputKind::kScans && landmarks_folder)
    throw CommandFailed(invalid_argument(
        args.landmarks.string() +
        ": range scans take one landmark file (the first scan's, then tracked), not a folder"));
  if (args.same_vertices && kind != InputKind::kMeshes)
    throw CommandFailed(invalid_argument("--same-vertices needs meshes, not range scans"));
  // A landmark file given for meshes is read now, so that a bad one stops the run before
  // anything is written.
  if (kind == InputKind::kMeshes && !args.landmarks.empty() && !landmarks_folder)
    value_or_throw(read_landmark_points(args.landmarks, 3));
  throw_if_error(ensure_directory(args.output));
  std::vector<Frame> frames(files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    frames[i].index = files[i].index;
    frames[i].path = files[i].path;
    if (kind != InputKind::kMeshes) continue;
    // The first frame takes --landmarks FILE; every frame its own file in --landmarks FOLDER,
    // else the one beside it.
    if (!args.landmarks.empty() && !landmarks_folder && i == 0)
      frames[i].landmark_file = args.landmarks;
    else
      frames[i].landmark_file =
          find_landmark_file(files[i].path, landmarks_folder ? args.landmarks : fs::path());
  }
  if (kind == InputKind::kMeshes && !args.landmarks.empty() && !landmarks_folder &&
      frames.size() > 1 && !args.same_vertices)
    logger().info(
        "--landmarks {} is the first frame's; the others use their own landmark files "
        "or detection",
        args.landmarks.string());
  LazyDetector lazy_detector(args.model);

  // --same-vertices: the first frame is cleaned, the others carry its cleaned face.
  struct Reference {
    Mesh input;
    facemap::CleanedFace face;
  };
  std::optional<Reference> reference;
  if (args.same_vertices) {
    Frame& first = frames.front();
    const std::string name = first.path.filename().string();
    Mesh input = value_or_throw(read_mesh(first.path, {.scale = scale}));
    if (!units_given) throw_if_error(check_face_size(input, name));
    nlohmann::json how;
    const FaceLandmarks landmarks = value_or_throw(
        mesh_frame_landmarks(first, input, {}, scale, args.detect, &lazy_detector, &how));
    first.mesh_input = {{"landmarks", how}};
    auto face = facemap::clean_mesh(input, landmarks, name, options);
    if (!face.is_ok())
      throw CommandFailed(face.status().with_context("--same-vertices reference frame"));
    reference = Reference{std::move(input), std::move(face).value()};
  }

  // Scans need the landmark detector (detection, or re-detection when tracking is lost).
  std::unique_ptr<facemap::LandmarkDetector> detector;
  if (kind == InputKind::kScans) {
    facemap::LandmarkDetectorOptions detector_options;
    detector_options.model_path = args.model;
    detector = std::make_unique<facemap::LandmarkDetector>(
        value_or_throw(facemap::LandmarkDetector::create(detector_options)));
  }

  // Tracking is sequential: landmarks for every frame first, then the frames in parallel.
  if (kind == InputKind::kScans && !args.landmarks.empty()) {
    const LandmarkPoints points = value_or_throw(read_landmark_points(args.landmarks, 2));
    if (points.dims != 2 || points.file_count != FaceLandmarks::kCount)
      throw CommandFailed(invalid_argument(
          args.landmarks.string() + ": range scans need the first scan's 68 image points (" +
          std::to_string(points.file_count) + " points of " + std::to_string(points.dims) +
          " coordinates given); 51-point and 3-D sets fit meshes"));
    const FaceLandmarks first = to_face_landmarks(points);
    std::unique_ptr<facemap::LandmarkTracker> tracker;
    Progress progress("tracking landmarks", static_cast<int64_t>(frames.size()));
    for (auto& frame : frames) {
      frame.landmark_file = args.landmarks;
      progress.advance();
      auto scan = read_range_scan_exr(frame.path);
      if (!scan.is_ok()) continue;  // reported again when the frame is processed
      if (!tracker) {
        tracker = std::make_unique<facemap::LandmarkTracker>(scan->texture, first, detector.get());
        frame.landmarks = first;
        continue;
      }
      auto tracked = tracker->track(scan->texture);
      if (tracked.is_ok()) {
        frame.landmarks = std::move(tracked).value();
      } else {
        frame.status = tracked.status().with_context("frame " + std::to_string(frame.index));
        // Start again from a fresh detection on this frame when possible.
        auto detected = detector->detect(scan->texture);
        if (detected.is_ok())
          tracker =
              std::make_unique<facemap::LandmarkTracker>(scan->texture, *detected, detector.get());
      }
    }
    progress.finish();
  }

  const nlohmann::json header = {
      {"command", "facemap clean"},
      {"input", args.input.string()},
      {"input_kind", kind == InputKind::kScans ? "range scans" : "meshes"},
      {"options", options_json(args)}};
  FrameStatsFile stats_file(args.output, header, args.resume);
  if (!stats_file.resume_note().empty()) logger().info("{}", stats_file.resume_note());
  std::vector<nlohmann::json> entries(frames.size());
  std::atomic<int> kept{0};
  std::optional<tbb::global_control> threads;
  if (args.threads > 0) threads.emplace(tbb::global_control::max_allowed_parallelism, args.threads);
  Progress progress("facemap clean", static_cast<int64_t>(frames.size()));
  const auto start = std::chrono::steady_clock::now();
  tbb::parallel_for(size_t{0}, frames.size(), [&](size_t i) {
    Frame& frame = frames[i];
    const std::string name = frame.path.filename().string();
    // A frame an earlier run finished is kept when its inputs (the frame's file and its
    // landmark file) have not changed since: a cleaned face whose files are complete, or a
    // failure (it would fail again the same way).
    if (auto previous = stats_file.previous(frame.index)) {
      const bool ok = previous->value("ok", false);
      std::vector<fs::path> inputs = {frame.path};
      if (frame.landmark_file) inputs.push_back(*frame.landmark_file);
      const bool same_inputs =
          !previous->contains("inputs") || (*previous)["inputs"] == input_fingerprint(inputs);
      if (same_inputs &&
          (!ok || all_exist({frame_path(args.output, frame.index, ".ply"),
                             frame_path(args.output, frame.index, ".landmarks.json")}))) {
        entries[i] = *previous;
        ++kept;
        if (Status s = stats_file.record(frame.index, entries[i]); !s)
          logger().warn("{}", s.message());
        progress.advance();
        return;
      }
    }
    // Each branch returns its Result directly (built in place): meshes have no cheap move.
    auto clean_frame = [&]() -> Result<facemap::CleanedFace> {
      if (kind == InputKind::kScans) {
        GVKIT_ASSIGN_OR_RETURN(RangeScan scan, read_range_scan_exr(frame.path));
        scan.index = frame.index;
        FaceLandmarks landmarks;
        if (frame.landmarks) {
          landmarks = *frame.landmarks;
        } else {
          auto detected = detector->detect(scan.texture);
          if (!detected.is_ok()) return detected.status().with_context(name);
          landmarks = std::move(detected).value();
        }
        return facemap::clean_scan(scan, std::move(landmarks), options);
      }
      if (reference) {
        if (frame.index == frames.front().index) return reference->face;
        GVKIT_ASSIGN_OR_RETURN(Mesh mesh, read_mesh(frame.path, {.scale = scale}));
        facemap::TransferStats transfer;
        auto face = facemap::transfer_cleaned_face(reference->face, reference->input, mesh, name,
                                                   &transfer);
        frame.transfer = transfer;
        return face;
      }
      // A raw mesh: read as the file has it, repaired, then its landmarks.
      GVKIT_ASSIGN_OR_RETURN(const TriangleSoup soup,
                             read_triangle_soup(frame.path, {.scale = scale}));
      frame.mesh_input["file"] = soup_json(soup, scale);
      facemap::SoupMeshOptions soup_options;
      soup_options.keep_largest_piece = !args.one_piece;
      soup_options.min_kept_area_share = args.min_piece_share;
      GVKIT_ASSIGN_OR_RETURN(facemap::SoupMesh repaired,
                             facemap::mesh_from_soup(soup, name, soup_options));
      frame.mesh_input["repair"] = repair_json(repaired.repair);
      if (!units_given) GVKIT_RETURN_IF_ERROR(check_face_size(repaired.mesh, name));
      nlohmann::json how;
      GVKIT_ASSIGN_OR_RETURN(const FaceLandmarks landmarks,
                             mesh_frame_landmarks(frame, repaired.mesh, repaired.texture, scale,
                                                  args.detect, &lazy_detector, &how));
      frame.mesh_input["landmarks"] = how;
      // Errors name the landmark file too: landmarks of another mesh lie off this one.
      const std::string context =
          frame.landmark_file
              ? name + " (landmarks " + frame.landmark_file->filename().string() + ")"
              : name;
      CleanOptions mesh_options = options;
      mesh_options.keep_largest_mesh_component = true;  // one piece already, after the repair
      auto face = facemap::clean_mesh(std::move(repaired.mesh), landmarks, context, mesh_options);
      if (face.is_ok()) {
        const std::string again = face->stats.repair;
        face->stats.repair = repaired.repair.summary();
        if (again != "no repair needed") face->stats.repair += "; then " + again;
      }
      return face;
    };
    auto process = [&]() -> Status {
      if (!frame.status.is_ok()) return frame.status;
      Result<facemap::CleanedFace> face = clean_frame();
      if (!face.is_ok()) return face.status();
      frame.stats = face->stats;
      GVKIT_RETURN_IF_ERROR(write_mesh(frame_path(args.output, frame.index, ".ply"), face->mesh));
      return write_face_landmarks(frame_path(args.output, frame.index, ".landmarks.json"),
                                  face->landmarks);
    };
    try {
      frame.status = process();
    } catch (const std::exception& e) {
      frame.status = Status(StatusCode::kInternal, name + ": " + e.what());
    }
    if (!frame.status.is_ok()) logger().warn("skipped: {}", frame.status.message());
    entries[i] = frame_json(frame);
    if (Status s = stats_file.record(frame.index, entries[i]); !s) logger().warn("{}", s.message());
    progress.advance();
  });
  progress.finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (kept > 0)
    logger().info("facemap clean: {} of {} frames were already done in {}; kept, not recomputed",
                  kept.load(), frames.size(), args.output.string());

  nlohmann::json per_frame = nlohmann::json::array();
  int ok = 0;
  double total_ms = 0.0;
  std::string first_error;
  for (const auto& entry : entries) {
    per_frame.push_back(entry);
    if (entry.value("ok", false)) {
      ++ok;
      if (entry.contains("ms")) total_ms += entry["ms"].value("total", 0.0);
    } else if (first_error.empty()) {
      first_error = entry.value("error", std::string("unknown error"));
    }
  }
  const nlohmann::json summary = {{"frames", frames.size()},
                                  {"ok", ok},
                                  {"failed", static_cast<int>(frames.size()) - ok},
                                  {"kept_from_earlier_run", kept.load()},
                                  {"mean_frame_ms", ok > 0 ? total_ms / ok : 0.0},
                                  {"wall_s", seconds}};
  throw_if_error(stats_file.finish(summary, per_frame));
  logger().info("facemap clean: {} of {} frames written to {}", ok, frames.size(),
                args.output.string());
  if (ok == 0)
    throw CommandFailed(
        failed_precondition("no frame could be cleaned; first error: " + first_error));
}

}  // namespace

void add_facemap_clean_command(CLI::App& facemap) {
  auto args = std::make_shared<CleanArgs>();
  CLI::App* cmd = facemap.add_subcommand(
      "clean", "Scans or meshes -> face meshes with 4 boundaries (rim, eyes, mouth) + landmarks");
  cmd->add_option("SCANS", args->input,
                  "Folder of frame_NNNNNN.exr range scans or frame_NNNNNN.ply/.obj meshes, or one "
                  "scan or mesh file (any name)")
      ->required();
  cmd->add_option("-o,--output", args->output, "Output folder")->required();
  cmd->add_option("--radius", args->options.mask.radius_mm,
                  "Geodesic mask radius from the eyes and mouth, mm (0: automatic)")
      ->capture_default_str();
  cmd->add_option("--radius-factor", args->options.mask.radius_factor,
                  "Automatic radius = this x the eyes-to-mouth distance")
      ->capture_default_str();
  cmd->add_option(
      "--landmarks", args->landmarks,
      "Landmark file (.npy, .txt, .csv, .pts, .json; 68 iBUG points or the 51 without the jaw) "
      "or a folder of them named like the meshes. Scans: the first scan's 68 image points, "
      "tracked through the others. Meshes: 3-D points in the mesh file's units, or pixels of "
      "its texture image; a file is the first frame's, a folder has one per frame. Meshes "
      "without any: the file beside them (NAME.landmarks.json, .npy, .txt, .csv, .pts), else "
      "detection");
  cmd->add_flag("!--no-detect", args->detect,
                "Meshes: fail a frame without a landmark file instead of running dlib on renders "
                "of the mesh (its texture image, vertex colours or shading)");
  cmd->add_option("--units", args->units,
                  "Meshes: the unit of the mesh files (and of their 3-D landmarks): mm, cm or m. "
                  "Without --units or --scale, a mesh whose size is not a face's in mm is refused "
                  "with a hint");
  cmd->add_option("--scale", args->scale,
                  "Meshes: millimetres per mesh file unit (instead of --units)");
  cmd->add_flag("--one-piece", args->one_piece,
                "Meshes: refuse a mesh in several pieces instead of keeping the largest");
  cmd->add_option("--min-piece-share", args->min_piece_share,
                  "Meshes: the largest piece must hold at least this share of the surface area "
                  "to be kept (the rest is debris: islands, loose hair)")
      ->capture_default_str();
  cmd->add_option("--mouth", args->mouth, "Mouth contour to cut: inner or outer")
      ->capture_default_str();
  cmd->add_option("--eye-margin", args->options.mask.eye_margin_mm,
                  "Grow the eye regions by this, mm")
      ->capture_default_str();
  cmd->add_option("--mouth-margin", args->options.mask.mouth_margin_mm,
                  "Grow the mouth region by this, mm")
      ->capture_default_str();
  cmd->add_option("--max-landmark-gap", args->options.landmark_max_gap_px,
                  "Scans: a landmark on no mesh pixel moves to the nearest one up to this far, px")
      ->capture_default_str();
  cmd->add_option("--max-landmark-snap", args->options.landmark_max_snap_mm,
                  "A landmark off the surface moves to the nearest vertex up to this far, mm")
      ->capture_default_str();
  cmd->add_flag("!--keep-feature-interiors", args->options.cut_feature_interiors,
                "Scans: keep what is seen inside the mouth and eye contours in the mesh");
  cmd->add_flag("--fill-feature-holes", args->options.fill_feature_holes,
                "Scans: fill the eye and mouth openings before masking like every other hole "
                "(the reference; the mask cuts them away either way)");
  cmd->add_option("--max-edge-factor", args->options.scan.max_edge_factor,
                  "Depth-discontinuity threshold in pixel footprints")
      ->capture_default_str();
  cmd->add_option("--model", args->model, "dlib 68-point shape predictor")->capture_default_str();
  cmd->add_option("--threads", args->threads, "Worker threads (0: all cores)")
      ->capture_default_str();
  cmd->add_flag("--same-vertices", args->same_vertices,
                "Meshes of one vertex layout (a registered sequence): clean the first frame and "
                "carry its face (vertices, cuts, landmarks) to the others through surface "
                "anchors, so all frames share the output layout (then `facemap map "
                "--same-vertices`); the other frames' landmark files are not read");
  cmd->add_flag("--resume", args->resume,
                "Keep the frames an earlier run with the same options finished in the output "
                "folder (listed in its stats.json, files present); compute only the others");
  cmd->callback([args] { run_clean(*args); });
}

}  // namespace gvkit::tools
