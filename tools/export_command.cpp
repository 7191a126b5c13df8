// gvkit export INPUT --format ply|obj|exr -o DIR: writes each frame of a geometry video as a
// triangle mesh (PLY/OBJ through OpenMesh) or as a geometry-image EXR.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
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
#include "tool_support.hpp"

namespace gvkit::tools {
namespace {
using namespace gvkit::player;

struct ExportCommandOptions {
  std::string input, output, format = "ply", frames = ":";
  bool ascii = false, partial_quads = true;
  double max_edge_mm = 0;
};

void run_export(const ExportCommandOptions& o) {
  if (o.format != "ply" && o.format != "obj" && o.format != "exr")
    throw CommandFailed(
        invalid_argument("--format must be ply, obj or exr, got '" + o.format + "'"));
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

  std::vector<std::string> failures;
  nlohmann::json per_frame = nlohmann::json::array();
  Progress progress("export", static_cast<int64_t>(indices.size()));
  const auto start = std::chrono::steady_clock::now();
  for (int64_t i : indices) {
    progress.advance();
    auto image = seq->frame(i);
    if (!image.is_ok()) {
      logger().warn("frame {}: {}", i, image.status().message());
      failures.push_back(image.status().message());
      continue;
    }
    nlohmann::json fj = {{"index", i}};
    if (o.format == "exr") {
      throw_if_error(write_geometry_image_exr(frame_path(o.output, i, ".exr"), *image));
      fj["domain_pixels"] = cv::countNonZero(image->domain_mask);
    } else {
      const MeshBuffers buffers = mesh_buffers_from_geometry_image(*image, mesh_options);
      int dropped = 0;
      const Mesh mesh = mesh_from_buffers(buffers, &dropped);
      if (mesh.n_faces() == 0) {
        failures.push_back("frame " + std::to_string(i) + ": no triangles (empty domain)");
        continue;
      }
      throw_if_error(write_mesh(frame_path(o.output, i, "." + o.format), mesh, write_options));
      fj["vertices"] = mesh.n_vertices();
      fj["faces"] = mesh.n_faces();
      fj["non_manifold_faces_dropped"] = dropped;
    }
    per_frame.push_back(fj);
  }
  progress.finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  throw_if_error(write_json(std::filesystem::path(o.output) / "stats.json",
                            {{"input", o.input},
                             {"frames", per_frame},
                             {"summary",
                              {{"written", per_frame.size()},
                               {"failed", failures.size()},
                               {"failures", failures},
                               {"seconds", seconds}}},
                             {"options",
                              {{"format", o.format},
                               {"frames", o.frames},
                               {"ascii", o.ascii},
                               {"max_edge_mm", o.max_edge_mm},
                               {"partial_quads", o.partial_quads},
                               {"fps", seq->fps()}}}}));
  std::printf("exported %zu of %zu frames as %s to %s\n", per_frame.size(), indices.size(),
              o.format.c_str(), o.output.c_str());
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
  cmd->add_option("--max-edge", o->max_edge_mm,
                  "Drop triangles with an edge longer than this (mm)");
  cmd->add_flag("!--no-partial-quads", o->partial_quads,
                "Triangulate only quads with all four pixels in the domain");
  cmd->callback([o] { run_export(*o); });
}

}  // namespace gvkit::tools
