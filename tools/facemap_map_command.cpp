// gvkit facemap map FACES -o GV [--size WxH] [--method eip|hm]: maps every face frame
// (frame_NNNNNN.ply + frame_NNNNNN.landmarks.json) onto the canonical domain and writes
// frame_NNNNNN.exr geometry images and stats.json (per-frame and summary metrics).
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "command.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/face_landmarks_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/log.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "gvkit/core/progress.hpp"
#include "gvkit/facemap/block_matching.hpp"
#include "gvkit/facemap/canonical_domain.hpp"
#include "gvkit/facemap/eip_map.hpp"
#include "gvkit/facemap/harmonic_map_baseline.hpp"
#include "gvkit/facemap/map_metrics.hpp"
#include "tool_support.hpp"

namespace gvkit::tools {
namespace {
namespace fs = std::filesystem;
using facemap::MappedFace;

struct MapCommandOptions {
  std::string faces, output, size = "320x320", method = "eip", domain, rim = "angle",
                             solver = "auto", exr_compression = "zip";
  int threads = 0;
  bool same_vertices = false;
  bool plain_cotan = false;
  bool png = false;
  bool resume = false;
};

// xyz normalized to the domain's bounding box as 8-bit RGB (x -> R, y -> G, z -> B); holes black.
cv::Mat preview(const GeometryImage& image) {
  cv::Vec3f lo(INFINITY, INFINITY, INFINITY), hi(-INFINITY, -INFINITY, -INFINITY);
  for (int y = 0; y < image.xyz_mm.rows; ++y)
    for (int x = 0; x < image.xyz_mm.cols; ++x)
      if (image.domain_mask.at<uint8_t>(y, x))
        for (int c = 0; c < 3; ++c) {
          lo[c] = std::min(lo[c], image.xyz_mm.at<cv::Vec3f>(y, x)[c]);
          hi[c] = std::max(hi[c], image.xyz_mm.at<cv::Vec3f>(y, x)[c]);
        }
  cv::Mat out(image.xyz_mm.size(), CV_8UC3, cv::Scalar::all(0));
  for (int y = 0; y < out.rows; ++y)
    for (int x = 0; x < out.cols; ++x) {
      if (!image.domain_mask.at<uint8_t>(y, x)) continue;
      const cv::Vec3f p = image.xyz_mm.at<cv::Vec3f>(y, x);
      cv::Vec3b& q = out.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c)  // OpenCV stores BGR: x goes to the red channel (index 2)
        q[2 - c] =
            cv::saturate_cast<uint8_t>(255.0 * (p[c] - lo[c]) / std::max(1e-6f, hi[c] - lo[c]));
    }
  return out;
}

const std::vector<int> kKeyLandmarks = {36, 39, 42, 45, 60, 64};

Result<cv::Size> parse_size(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X'))
    return invalid_argument("--size: expected WxH (e.g. 320x320), got '" + text + "'");
  if (w < 16 || h < 16 || w > 4096 || h > 4096)
    return invalid_argument("--size: width and height must be in 16..4096");
  return cv::Size(w, h);
}

// One frame after the parallel pass: its own figures (entry), and what the figures across frames
// need (landmarks in the domain, the geometry image).
struct FrameResult {
  int64_t index = 0;
  nlohmann::json entry;  // index, time_s, and either error or this frame's own figures
  bool ok = false;
  std::vector<Eigen::Vector2d> landmarks_px;
  GeometryImage image;
  std::optional<MappedFace> mapped;  // only with --same-vertices
  std::vector<cv::Vec3d> positions;  // only with --same-vertices
};

// The figures of one mapped frame that do not depend on other frames.
nlohmann::json own_entry(const FrameResult& r, const MappedFace& m, const std::string& method,
                         int flipped, double seconds) {
  nlohmann::json f = {{"index", r.index}, {"time_s", seconds}};
  f["flipped"] = flipped;
  f["corner_image_flipped"] = m.quality.flipped;
  f["triangles"] = m.quality.triangles;
  f["eps_angle"] = m.quality.eps_angle;
  f["eps_area"] = m.quality.eps_area;
  f["unmapped_pixels"] = m.unmapped_pixels;
  f["interior_extrema"] = m.interior_extrema;
  f["boundary_nonmonotone"] = m.boundary_nonmonotone;
  if (method == "eip") {
    f["untangled_vertices"] = m.st_untangled;
    f["cut_method"] = m.cut_method;
    const auto& t = m.timing;
    f["cpu_ms"] = {{"annulus", t.annulus_ms},
                   {"cut_distances", t.cut_distance_ms},
                   {"laplacian", t.laplacian_ms},
                   {"order", t.order_ms},
                   {"f", t.f_ms},
                   {"psi", t.psi_ms},
                   {"correspondence", t.correspondence_ms},
                   {"untangle", t.untangle_ms},
                   {"resample", t.resample_ms},
                   {"landmarks", t.landmarks_ms},
                   {"quality", t.quality_ms},
                   {"total", t.total_ms}};
  }
  if (!m.warnings.empty()) f["warnings"] = m.warnings;
  nlohmann::json landmarks = nlohmann::json::array();
  for (const auto& p : m.landmarks_px) landmarks.push_back({p.x(), p.y()});
  f["landmarks_px"] = landmarks;
  return f;
}

// An earlier run's frame, when its entry and files are complete: the entry without the figures
// across frames (computed again), the landmarks and the image read back.
bool keep_previous(const MapCommandOptions& o, const nlohmann::json& previous, FrameResult& r) {
  if (previous.contains("error")) {
    r.entry = previous;
    return true;
  }
  if (!previous.contains("landmarks_px") || !previous["landmarks_px"].is_array()) return false;
  std::vector<fs::path> files = {frame_path(o.output, r.index, ".exr")};
  if (o.png) files.push_back(frame_path(o.output, r.index, ".png"));
  if (!all_exist(files)) return false;
  auto image = read_geometry_image_exr(files.front());
  if (!image.is_ok()) return false;
  r.image = std::move(image).value();
  for (const auto& p : previous["landmarks_px"])
    r.landmarks_px.emplace_back(p.at(0).get<double>(), p.at(1).get<double>());
  r.entry = previous;
  for (const char* key :
       {"key_feature_drift_px", "feature_drift_px", "temporal_mse_mm2", "temporal_mse_mean_mm2",
        "temporal_mse_area_weighted_mm2", "true_drift_mm"})
    r.entry.erase(key);
  r.ok = true;
  return true;
}

nlohmann::json drift_json(const facemap::DriftStats& d) {
  return {{"count", d.count}, {"mean", d.mean}, {"rms", d.rms}, {"max", d.max}};
}

void run(const MapCommandOptions& o) {
  const cv::Size size = value_or_throw(parse_size(o.size));
  const ExrCompression compression = value_or_throw(exr_compression_option(o.exr_compression));
  if (o.method != "eip" && o.method != "hm")
    throw CommandFailed(invalid_argument("--method must be eip or hm, got '" + o.method + "'"));
  if (o.rim != "arclength" && o.rim != "flow" && o.rim != "angle")
    throw CommandFailed(
        invalid_argument("--rim must be arclength, angle or flow, got '" + o.rim + "'"));
  if (o.threads < 0) throw CommandFailed(invalid_argument("--threads must be >= 0"));
  if (o.solver != "auto" && o.solver != "direct" && o.solver != "multigrid")
    throw CommandFailed(
        invalid_argument("--solver must be auto, direct or multigrid, got '" + o.solver + "'"));
  facemap::EipOptions eip_options;
  eip_options.solver = o.solver == "direct"      ? facemap::HarmonicSolver::kDirect
                       : o.solver == "multigrid" ? facemap::HarmonicSolver::kMultigrid
                                                 : facemap::HarmonicSolver::kAuto;
  const auto meshes = value_or_throw(list_frame_files(o.faces, ".ply"));
  if (meshes.empty()) throw CommandFailed(not_found(o.faces + ": no frame_NNNNNN.ply files"));
  throw_if_error(ensure_directory(o.output));

  std::optional<facemap::CanonicalDomain> domain;
  if (o.method == "eip") {
    const auto spec = o.domain.empty()
                          ? value_or_throw(facemap::CanonicalDomainSpec::load_default())
                          : value_or_throw(facemap::CanonicalDomainSpec::read(o.domain));
    const auto rim = o.rim == "flow"    ? facemap::RimCorrespondence::kFlow
                     : o.rim == "angle" ? facemap::RimCorrespondence::kAngle
                                        : facemap::RimCorrespondence::kArcLength;
    const double floor =
        o.plain_cotan ? -std::numeric_limits<double>::infinity() : facemap::kDefaultMinCotanWeight;
    domain = value_or_throw(facemap::CanonicalDomain::create(spec, size, rim, floor));
  }
  std::unique_ptr<tbb::global_control> limit;
  if (o.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  o.threads);

  const nlohmann::json options = {{"faces", o.faces},
                                  {"size", o.size},
                                  {"method", o.method},
                                  {"rim", o.rim},
                                  {"plain_cotan", o.plain_cotan},
                                  {"solver", o.solver},
                                  {"domain", o.domain},
                                  {"threads", o.threads},
                                  {"same_vertices", o.same_vertices},
                                  {"png", o.png},
                                  {"exr_compression", o.exr_compression},
                                  {"block_matching", {{"block_size", 16}, {"search_range", 16}}}};
  // --same-vertices needs every frame's mapping in memory: no frame is kept from earlier runs.
  FrameStatsFile stats_file(o.output, {{"command", "facemap map"}, {"options", options}},
                            o.resume && !o.same_vertices);
  if (!stats_file.resume_note().empty()) logger().info("{}", stats_file.resume_note());
  std::vector<FrameResult> results(meshes.size());
  std::atomic<int> kept{0};
  Progress progress("facemap map", static_cast<int64_t>(meshes.size()));
  const auto distance = facemap::heat_geodesic_distance();
  tbb::parallel_for(size_t{0}, meshes.size(), [&](size_t i) {
    FrameResult& r = results[i];
    r.index = meshes[i].index;
    auto record = [&] {
      if (Status s = stats_file.record(r.index, r.entry); !s) logger().warn("{}", s.message());
      progress.advance();
    };
    if (auto previous = stats_file.previous(r.index); previous && keep_previous(o, *previous, r)) {
      ++kept;
      return record();
    }
    const auto start = std::chrono::steady_clock::now();
    auto fail = [&](const Status& s) {
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      r.entry = {{"index", r.index}, {"time_s", seconds}, {"error", s.message()}};
      record();
    };
    auto mesh = read_mesh(meshes[i].path);
    auto landmarks = read_face_landmarks(frame_path(o.faces, r.index, ".landmarks.json"));
    if (!mesh.is_ok()) return fail(mesh.status());
    if (!landmarks.is_ok()) return fail(landmarks.status());
    Result<MappedFace> mapped =
        o.method == "eip" ? facemap::map_face_eip(*mesh, *landmarks, *domain, distance, eip_options)
                          : facemap::map_face_hm(*mesh, *landmarks, size);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!mapped.is_ok())
      return fail(mapped.status().with_context(meshes[i].path.filename().string()));
    mapped->image.index = r.index;
    const Status written =
        write_geometry_image_exr(frame_path(o.output, r.index, ".exr"), mapped->image, compression);
    const Status png =
        o.png ? write_image(frame_path(o.output, r.index, ".png"), preview(mapped->image))
              : Status::ok();
    if (!written.is_ok() || !png.is_ok()) return fail(written.is_ok() ? png : written);
    const int flipped =
        o.method == "eip" ? mapped->st_flipped + domain->flow().flipped : mapped->quality.flipped;
    r.entry = own_entry(r, *mapped, o.method, flipped, seconds);
    r.landmarks_px = mapped->landmarks_px;
    r.ok = true;
    if (o.same_vertices) {
      for (auto v : mesh->vertices())
        r.positions.emplace_back(mesh->point(v)[0], mesh->point(v)[1], mesh->point(v)[2]);
      r.image = mapped->image;
      r.mapped = std::move(*mapped);
    } else {
      r.image = std::move(mapped->image);
    }
    record();
  });
  progress.finish();
  if (kept > 0)
    logger().info("facemap map: {} of {} frames were already done in {}; kept, not recomputed",
                  kept.load(), results.size(), o.output);

  // Metrics across frames (sequential): against frame 0 and the previous mapped frame.
  nlohmann::json frames = nlohmann::json::array();
  const FrameResult* first = nullptr;
  const FrameResult* previous = nullptr;
  // --same-vertices: the previous frame as frame 0's pixels carried through the correspondence.
  std::optional<GeometryImage> previous_carried;
  int ok = 0, total_flipped = 0;
  double sum_angle = 0, sum_area = 0, sum_time = 0, sum_key = 0, max_key = 0, sum_all = 0;
  std::array<double, 3> sum_mse{};
  double sum_mse_mean = 0, sum_mse_area = 0, sum_true = 0, sum_carried_mse = 0,
         sum_carried_area = 0;
  int n_mse = 0, n_true = 0, n_carried_mse = 0;
  std::vector<int> all(68);
  for (int i = 0; i < 68; ++i) all[i] = i;
  for (const FrameResult& r : results) {
    nlohmann::json f = r.entry;
    if (!r.ok) {
      std::fprintf(stderr, "frame %lld: %s\n", static_cast<long long>(r.index),
                   f.value("error", std::string("unknown error")).c_str());
      frames.push_back(f);
      continue;
    }
    if (!first) first = &r;
    const auto key = facemap::feature_drift(first->landmarks_px, r.landmarks_px, kKeyLandmarks);
    const auto every = facemap::feature_drift(first->landmarks_px, r.landmarks_px, all);
    f["key_feature_drift_px"] = drift_json(key);
    f["feature_drift_px"] = drift_json(every);
    if (previous) {
      const auto bm = facemap::block_matching_error(previous->image, r.image);
      if (bm.is_ok()) {
        f["temporal_mse_mm2"] = {bm->mse_mm2[0], bm->mse_mm2[1], bm->mse_mm2[2]};
        f["temporal_mse_mean_mm2"] = bm->mean_mse_mm2;
        f["temporal_mse_area_weighted_mm2"] = bm->area_weighted_mean_mse_mm2;
        sum_mse_area += bm->area_weighted_mean_mse_mm2;
        for (int c = 0; c < 3; ++c) sum_mse[c] += bm->mse_mm2[c];
        sum_mse_mean += bm->mean_mse_mm2;
        ++n_mse;
      }
    }
    if (o.same_vertices && first != &r && first->positions.size() == r.positions.size()) {
      const auto td = facemap::true_surface_drift(*first->mapped, *r.mapped, r.positions);
      f["true_drift_mm"] = drift_json(td);
      if (domain) {
        const MappedFace& m = *r.mapped;
        // RMS drift per band of t (0 at the rim, 1 at the eyes, mouth and cuts).
        std::array<double, 4> sum2{};
        std::array<int, 4> count{};
        for (size_t p = 0; p < m.pixel_source.size(); ++p) {
          const auto& a = first->mapped->pixel_source[p];
          const auto& b = m.pixel_source[p];
          if (a.empty() || b.empty()) continue;
          cv::Vec3d pa(0, 0, 0), pb(0, 0, 0);
          for (const auto& w : a) pa += w.weight * r.positions[w.vertex];
          for (const auto& w : b) pb += w.weight * r.positions[w.vertex];
          const double t =
              domain->st(static_cast<int>(p) % size.width, static_cast<int>(p) / size.width).y();
          const int band = std::clamp(static_cast<int>(t * 4), 0, 3);
          sum2[band] += cv::norm(pa - pb) * cv::norm(pa - pb);
          ++count[band];
        }
        nlohmann::json bands = nlohmann::json::array();
        for (int k = 0; k < 4; ++k) bands.push_back(count[k] ? std::sqrt(sum2[k] / count[k]) : 0.0);
        f["true_drift_rms_mm_by_t_quarter"] = bands;
      }
      sum_true += td.rms * td.rms;
      ++n_true;
    }
    if (o.same_vertices && first->positions.size() == r.positions.size()) {
      // The same temporal MSE for a map without drift: frame 0's layout carried to this frame.
      GeometryImage carried = facemap::carried_geometry_image(*first->mapped, r.positions);
      if (previous_carried) {
        const auto bm = facemap::block_matching_error(*previous_carried, carried);
        if (bm.is_ok()) {
          f["temporal_mse_drift_free_mean_mm2"] = bm->mean_mse_mm2;
          f["temporal_mse_drift_free_area_weighted_mm2"] = bm->area_weighted_mean_mse_mm2;
          sum_carried_mse += bm->mean_mse_mm2;
          sum_carried_area += bm->area_weighted_mean_mse_mm2;
          ++n_carried_mse;
        }
      }
      previous_carried = std::move(carried);
    } else if (o.same_vertices && first != &r) {
      // Different vertex counts: the frames do not share a layout (e.g. each cleaned on its own;
      // `facemap clean --same-vertices` keeps one layout), so there is no true drift to measure.
      logger().warn("frame {}: {} vertices against {} in frame {}; no true surface drift", r.index,
                    r.positions.size(), first->positions.size(), first->index);
    }
    ++ok;
    total_flipped += f.value("flipped", 0);
    sum_angle += f.value("eps_angle", 0.0);
    sum_area += f.value("eps_area", 0.0);
    sum_time += f.value("time_s", 0.0);
    sum_key += key.mean;
    max_key = std::max(max_key, key.max);
    sum_all += every.mean;
    frames.push_back(f);
    previous = &r;
  }
  nlohmann::json summary = {{"frames", results.size()},
                            {"mapped", ok},
                            {"failed", static_cast<int>(results.size()) - ok},
                            {"flipped_total", total_flipped}};
  if (ok > 0) {
    summary["eps_angle_mean"] = sum_angle / ok;
    summary["eps_area_mean"] = sum_area / ok;
    summary["map_time_s_mean"] = sum_time / ok;
    summary["key_feature_drift_px_mean"] = sum_key / ok;
    summary["key_feature_drift_px_max"] = max_key;
    summary["feature_drift_px_mean"] = sum_all / ok;
  }
  if (n_mse > 0) {
    summary["temporal_mse_mm2"] = {sum_mse[0] / n_mse, sum_mse[1] / n_mse, sum_mse[2] / n_mse};
    summary["temporal_mse_mean_mm2"] = sum_mse_mean / n_mse;
    summary["temporal_mse_area_weighted_mm2"] = sum_mse_area / n_mse;
  }
  if (n_true > 0) summary["true_drift_rms_mm"] = std::sqrt(sum_true / n_true);
  if (n_carried_mse > 0) {
    summary["temporal_mse_drift_free_mean_mm2"] = sum_carried_mse / n_carried_mse;
    summary["temporal_mse_drift_free_area_weighted_mm2"] = sum_carried_area / n_carried_mse;
  }
  summary["kept_from_earlier_run"] = kept.load();
  throw_if_error(stats_file.finish(summary, frames));
  std::printf("%s: %d of %zu frames mapped (%s, %dx%d), %d flipped triangles\n", o.output.c_str(),
              ok, results.size(), o.method.c_str(), size.width, size.height, total_flipped);
  if (ok == 0) throw CommandFailed(failed_precondition("no frame could be mapped"));
}

}  // namespace

void add_facemap_map_command(CLI::App& app) {
  auto* cmd = facemap_group(app)->add_subcommand(
      "map", "Map face frames (PLY + landmarks JSON) to geometry images on the canonical domain");
  auto o = std::make_shared<MapCommandOptions>();
  cmd->add_option("faces", o->faces, "Folder of frame_NNNNNN.ply + frame_NNNNNN.landmarks.json")
      ->required();
  cmd->add_option("-o,--output", o->output, "Output folder (frame_NNNNNN.exr, stats.json)")
      ->required();
  cmd->add_option("--size", o->size, "Geometry image size WxH")->capture_default_str();
  cmd->add_option("--method", o->method, "eip (expression-invariant) or hm (harmonic map)")
      ->capture_default_str();
  cmd->add_option("--rim", o->rim,
                  "EIP rim correspondence: arclength (s blended with the rim's arc length from "
                  "the nose-chin anchor), angle (with the angle around the nose tip) or flow (s "
                  "where the integral curves arrive, the seed's)")
      ->capture_default_str();
  cmd->add_flag("--plain-cotan", o->plain_cotan,
                "EIP: solve f and its conjugate with the plain cotangent weights, negative ones "
                "included (the seed's; default: every edge weight floored at 0.005, so f has no "
                "interior extrema)");
  cmd->add_option("--solver", o->solver,
                  "EIP: how f and its conjugate are solved: direct (sparse LDL'), multigrid "
                  "(conjugate gradients with an algebraic multigrid preconditioner, to a relative "
                  "residual of 1e-8) or "
                  "auto (multigrid from 30,000 vertices on)")
      ->capture_default_str();
  cmd->add_option("--domain", o->domain, "Canonical domain JSON (default: the shipped v1)");
  cmd->add_option("--threads", o->threads, "Worker threads (0 = all cores)")->capture_default_str();
  cmd->add_flag("--same-vertices", o->same_vertices,
                "Frames share vertex order (ground-truth correspondence): also measure the true "
                "surface drift at fixed pixels");
  cmd->add_flag("--png", o->png, "Also write frame_NNNNNN.png previews (xyz as RGB)");
  cmd->add_option("--exr-compression", o->exr_compression, kExrCompressionHelp)
      ->capture_default_str();
  cmd->add_flag("--resume", o->resume,
                "Keep the frames an earlier run with the same options finished in the output "
                "folder (listed in its stats.json, files present); map only the others");
  cmd->callback([o] { run(*o); });
}

}  // namespace gvkit::tools
