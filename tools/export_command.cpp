// gvkit export INPUT --format ply|obj|exr -o DIR: writes each frame of a geometry video as a
// triangle mesh (PLY/OBJ; a manifold frame straight from its arrays, the rest through an
// OpenMesh mesh) or as a geometry-image EXR; frames are decoded in order and meshed and written
// on worker threads.
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/log.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "gvkit/core/progress.hpp"
#include "gvkit/player/frame_range.hpp"
#include "gvkit/player/frame_sequence.hpp"
#include "gvkit/player/geometry_image_mesh.hpp"
#include "gvkit/player/manifold_verdict_cache.hpp"
#include "tool_support.hpp"

namespace gvkit::tools {
namespace {
using namespace gvkit::player;

struct ExportCommandOptions {
  std::string input, output, format = "ply", frames = ":", exr_compression = "zip";
  bool ascii = false, partial_quads = true;
  double max_edge_mm = 0;
  // Workers; 0 = two per hardware thread, at most 8: a worker waits while its file reaches the
  // disk (write_file_atomically's fsync), and the other one keeps the core busy meanwhile.
  int threads = 0;
};

// One decoded frame's file, written on a worker: its stats.json entry, or why it failed
// (fatal: a write error, which stops the export as before).
struct ExportResult {
  int64_t index = 0;
  nlohmann::json stats;
  std::string failure;
  Status fatal = Status::ok();
};

ExportResult export_frame(int64_t i, const GeometryImage& image, const ExportCommandOptions& o,
                          ExrCompression compression, const GeometryImageMeshOptions& mesh_options,
                          const MeshWriteOptions& write_options, ManifoldVerdictCache& verdicts) {
  ExportResult r;
  r.index = i;
  r.stats = {{"index", i}};
  if (o.format == "exr") {
    r.fatal = write_geometry_image_exr(frame_path(o.output, i, ".exr"), image, compression);
    r.stats["domain_pixels"] = cv::countNonZero(image.domain_mask);
    return r;
  }
  const MeshBuffers buffers = mesh_buffers_from_geometry_image(image, mesh_options);
  const std::filesystem::path path = frame_path(o.output, i, "." + o.format);
  if (buffers.triangle_count() > 0 && verdicts.manifold(buffers, mesh_options)) {
    // OpenMesh would take every triangle: the file is written from the arrays, without building
    // the halfedge mesh (the same file; player/geometry_image_mesh.hpp).
    r.fatal = write_mesh_arrays(path, mesh_arrays(buffers), write_options);
    r.stats["vertices"] = buffers.vertex_count();
    r.stats["faces"] = buffers.triangle_count();
    r.stats["non_manifold_faces_dropped"] = 0;
    return r;
  }
  int dropped = 0;
  const Mesh mesh = mesh_from_buffers(buffers, &dropped);
  if (mesh.n_faces() == 0) {
    r.failure = "frame " + std::to_string(i) + ": no triangles (empty domain)";
    return r;
  }
  r.fatal = write_mesh(path, mesh, write_options);
  r.stats["vertices"] = mesh.n_vertices();
  r.stats["faces"] = mesh.n_faces();
  r.stats["non_manifold_faces_dropped"] = dropped;
  return r;
}

// Frames are decoded in order on the calling thread (P and B frames need the frames before
// them) and meshed and written on `threads` workers, at most 2 x threads frames in flight.
class ExportWorkers {
 public:
  ExportWorkers(int threads, std::function<ExportResult(int64_t, const GeometryImage&)> work)
      : work_(std::move(work)) {
    for (int t = 0; t < threads; ++t) threads_.emplace_back([this] { run(); });
    capacity_ = 2 * static_cast<size_t>(threads);
  }
  ~ExportWorkers() { finish(); }

  void push(int64_t index, GeometryImage image) {
    std::unique_lock<std::mutex> lock(mutex_);
    space_.wait(lock, [&] { return jobs_.size() < capacity_; });
    jobs_.push_back({index, std::move(image)});
    ready_.notify_one();
  }
  // Waits for every job; returns the results in frame order.
  std::vector<ExportResult> finish() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
    for (std::thread& t : threads_) t.join();
    threads_.clear();
    std::sort(results_.begin(), results_.end(),
              [](const ExportResult& a, const ExportResult& b) { return a.index < b.index; });
    return std::move(results_);
  }

 private:
  void run() {
    for (;;) {
      std::pair<int64_t, GeometryImage> job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait(lock, [&] { return closed_ || !jobs_.empty(); });
        if (jobs_.empty()) return;
        job = std::move(jobs_.front());
        jobs_.pop_front();
        space_.notify_one();
      }
      ExportResult r = work_(job.first, job.second);
      std::lock_guard<std::mutex> lock(mutex_);
      results_.push_back(std::move(r));
    }
  }

  std::function<ExportResult(int64_t, const GeometryImage&)> work_;
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable ready_, space_;
  std::deque<std::pair<int64_t, GeometryImage>> jobs_;
  std::vector<ExportResult> results_;
  size_t capacity_ = 2;
  bool closed_ = false;
};

void run_export(const ExportCommandOptions& o) {
  const ExrCompression compression = value_or_throw(exr_compression_option(o.exr_compression));
  if (o.format != "ply" && o.format != "obj" && o.format != "exr")
    throw CommandFailed(
        invalid_argument("--format must be ply, obj or exr, got '" + o.format + "'"));
  if (o.threads < 0 || o.threads > 64)
    throw CommandFailed(invalid_argument("--threads must be 0..64 (0 = automatic)"));
  GeometryImageMeshOptions mesh_options;
  mesh_options.max_edge_mm = o.max_edge_mm;
  mesh_options.partial_quads = o.partial_quads;
  throw_if_error(mesh_options.check());
  auto seq = value_or_throw(FrameSequence::create(o.input));
  const std::vector<int64_t> indices =
      value_or_throw(value_or_throw(parse_frame_range(o.frames)).indices(seq->frame_count()));
  throw_if_error(ensure_directory(o.output));
  MeshWriteOptions write_options;
  write_options.binary = !o.ascii;
  write_options.vertex_normals = true;
  const int threads = o.threads > 0 ? o.threads : 2 * command_threads(0, 4);
  std::vector<std::string> failures;
  nlohmann::json per_frame = nlohmann::json::array();
  Progress progress("export", static_cast<int64_t>(indices.size()));
  const auto start = std::chrono::steady_clock::now();
  ManifoldVerdictCache verdicts;  // the frames share their domain: one check per video
  ExportWorkers workers(threads, [&](int64_t i, const GeometryImage& image) {
    return export_frame(i, image, o, compression, mesh_options, write_options, verdicts);
  });
  for (int64_t i : indices) {
    progress.advance();
    auto image = seq->frame(i);
    if (!image.is_ok()) {
      logger().warn("frame {}: {}", i, image.status().message());
      failures.push_back(image.status().message());
      continue;
    }
    workers.push(i, std::move(image).value());
  }
  for (ExportResult& r : workers.finish()) {
    throw_if_error(r.fatal);
    if (!r.failure.empty()) {
      failures.push_back(r.failure);
      continue;
    }
    per_frame.push_back(std::move(r.stats));
  }
  progress.finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  throw_if_error(
      write_json(std::filesystem::path(o.output) / "stats.json",
                 {{"input", o.input},
                  {"frames", per_frame},
                  {"summary",
                   {{"written", per_frame.size()},
                    {"failed", failures.size()},
                    {"failures", failures},
                    {"seconds", seconds},
                    {"frames_per_second", seconds > 0 ? per_frame.size() / seconds : 0.0}}},
                  {"options",
                   {{"format", o.format},
                    {"frames", o.frames},
                    {"ascii", o.ascii},
                    {"exr_compression", o.exr_compression},
                    {"max_edge_mm", o.max_edge_mm},
                    {"partial_quads", o.partial_quads},
                    {"threads", threads},
                    {"fps", seq->fps()}}}}));
  std::printf("exported %zu of %zu frames as %s to %s in %.2f s (%.1f frames/s)\n",
              per_frame.size(), indices.size(), o.format.c_str(), o.output.c_str(), seconds,
              seconds > 0 ? per_frame.size() / seconds : 0.0);
  throw_if_error(failures_status(failures, indices.size()));
}

}  // namespace

void add_export_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "export", "Export geometry-video frames as meshes (PLY/OBJ) or geometry-image EXRs");
  auto o = std::make_shared<ExportCommandOptions>();
  cmd->add_option("input", o->input, "Geometry video: FILE.gvid or a folder of frame_NNNNNN.exr")
      ->required();
  cmd->add_option("--format", o->format, "ply, obj or exr")->capture_default_str();
  cmd->add_option("-o,--output", o->output, "Output folder (frame_NNNNNN.<format> + stats.json)")
      ->required();
  cmd->add_option("--frames", o->frames, "Frames A:B (half-open), A:, :B or N")
      ->capture_default_str();
  cmd->add_flag("--ascii", o->ascii, "ASCII PLY instead of binary");
  cmd->add_option("--exr-compression", o->exr_compression,
                  std::string("With --format exr: ") + kExrCompressionHelp)
      ->capture_default_str();
  cmd->add_option("--max-edge", o->max_edge_mm,
                  "Drop triangles with an edge longer than this (mm)");
  cmd->add_flag("!--no-partial-quads", o->partial_quads,
                "Triangulate only quads with all four pixels in the domain");
  cmd->add_option("--threads", o->threads,
                  "Frames meshed and written in parallel (0 = two per hardware thread, at most 8, "
                  "as each waits while its file reaches the disk; the files do not depend on it)")
      ->capture_default_str();
  cmd->callback([o] { run_export(*o); });
}

}  // namespace gvkit::tools
