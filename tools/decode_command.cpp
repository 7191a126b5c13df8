// gvkit decode FILE.gvid -o DIR: writes every decodable frame as DIR/frame_NNNNNN.exr and
// DIR/stats.json; a damaged frame is reported and skipped, and the command then fails. With
// --reference GV_DIR (the encoder's input) stats.json also holds each frame's point error (PSNR,
// RMS, max) and surface error (normal-angle error, Hausdorff distance) and their summary.
// Frames are decoded in order and written and measured on worker threads.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/parallel_pipeline.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/surface_metrics.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/log.hpp"
#include "gvkit/core/progress.hpp"
#include "surface_error_json.hpp"
#include "tool_support.hpp"

namespace gvkit::tools {
namespace {

struct DecodeArgs {
  std::string input, output, reference;
  int threads = 0;  // 0 = the hardware threads, at most 16
  std::string exr_compression = "zip";
};

nlohmann::json psnr_json(double psnr) {
  return std::isfinite(psnr) ? nlohmann::json(psnr) : nlohmann::json("inf");
}

void run_decode(const DecodeArgs& args) {
  if (args.threads < 0 || args.threads > 16)
    throw CommandFailed(invalid_argument("--threads must be 0..16 (0 = automatic)"));
  const ExrCompression compression = value_or_throw(exr_compression_option(args.exr_compression));
  auto reader = value_or_throw(codec::GvidReader::open(args.input));
  throw_if_error(ensure_directory(args.output));
  if (reader->index_rebuilt())
    logger().warn(
        "{}: the seek index is missing or damaged (a cut or damaged file): {} frames found by a "
        "scan; frames after a cut are lost",
        args.input, reader->frame_count());
  const codec::SequenceInfo& info = reader->info();
  const double vertices = static_cast<double>(info.domain_pixels());
  std::vector<FrameFile> reference_files;
  if (!args.reference.empty()) {
    reference_files = value_or_throw(list_frame_files(args.reference, ".exr"));
    if (static_cast<int64_t>(reference_files.size()) != reader->frame_count())
      throw CommandFailed(invalid_argument(
          "--reference " + args.reference + ": " + std::to_string(reference_files.size()) +
          " frame_NNNNNN.exr files for " + std::to_string(reader->frame_count()) + " frames"));
  }
  codec::GeometryError point_total;
  codec::SurfaceError surface_total;
  nlohmann::json frames = nlohmann::json::array();
  int64_t failed = 0;
  std::string first_error;
  double decode_seconds = 0;
  Progress progress("decoding", reader->frame_count());
  // Frames are decoded in order (P and B frames need the frames before them), written and
  // measured on workers (a TBB pipeline within --threads threads), and recorded in order.
  struct Decoded {
    int64_t index = 0;
    Result<GeometryImage> frame = GeometryImage();
    nlohmann::json entry;
    codec::GeometryError error;
    codec::SurfaceError surface;
  };
  int64_t next = 0;
  const auto decode = [&](tbb::flow_control& control) -> std::shared_ptr<Decoded> {
    if (next >= reader->frame_count()) {
      control.stop();
      return nullptr;
    }
    auto d = std::make_shared<Decoded>();
    d->index = next++;
    const auto start = std::chrono::steady_clock::now();
    d->frame = reader->decode_frame(d->index);
    decode_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    d->entry = {{"frame", d->index},
                {"bits", reader->frame_bits(d->index)},
                {"bits_per_vertex", reader->frame_bits(d->index) / vertices}};
    return d;
  };
  const auto write_and_measure = [&](std::shared_ptr<Decoded> d) {
    if (!d->frame.is_ok()) return d;
    const GeometryImage& frame = *d->frame;
    throw_if_error(
        write_geometry_image_exr(frame_path(args.output, d->index, ".exr"), frame, compression));
    d->entry["status"] = "ok";
    if (!reference_files.empty()) {
      const auto& path = reference_files[static_cast<size_t>(d->index)].path;
      const GeometryImage reference = value_or_throw(read_geometry_image_exr(path));
      if (reference.size() != frame.size())
        throw CommandFailed(invalid_argument(
            path.string() + ": size " + std::to_string(reference.size().width) + "x" +
            std::to_string(reference.size().height) + " differs from the stream's"));
      d->error = codec::geometry_error(reference, frame);
      d->surface = codec::surface_error(reference, frame);
      d->entry["psnr_db"] = psnr_json(d->error.psnr_db(info.box_diagonal_mm()));
      d->entry["rms_mm"] = d->error.rms_mm;
      d->entry["max_mm"] = d->error.max_mm;
      d->entry.update(surface_error_json(d->surface));
    }
    d->frame = GeometryImage();  // written: its memory goes back now
    return d;
  };
  const auto record = [&](const std::shared_ptr<Decoded>& d) {
    if (d->frame.is_ok()) {
      if (!reference_files.empty()) {
        codec::accumulate(point_total, d->error);
        codec::accumulate(surface_total, d->surface);
      }
    } else {
      ++failed;
      if (first_error.empty()) first_error = d->frame.status().message();
      logger().warn("{}", d->frame.status().message());
      d->entry["status"] = d->frame.status().message();
    }
    frames.push_back(std::move(d->entry));
    progress.advance();
  };
  const int threads = command_threads(args.threads, 16);
  {
    tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism,
                                    static_cast<size_t>(threads));
    tbb::parallel_pipeline(2 * static_cast<size_t>(threads),
                           tbb::make_filter<void, std::shared_ptr<Decoded>>(
                               tbb::filter_mode::serial_in_order, decode) &
                               tbb::make_filter<std::shared_ptr<Decoded>, std::shared_ptr<Decoded>>(
                                   tbb::filter_mode::parallel, write_and_measure) &
                               tbb::make_filter<std::shared_ptr<Decoded>, void>(
                                   tbb::filter_mode::serial_in_order, record));
  }
  progress.finish();
  const double n = static_cast<double>(reader->frame_count());
  nlohmann::json stats = {{"input", args.input},
                          {"output", args.output},
                          {"exr_compression", exr_compression_name(compression)},
                          {"summary",
                           {{"frames", reader->frame_count()},
                            {"failed_frames", failed},
                            {"width", info.width},
                            {"height", info.height},
                            {"bit_depth", info.bit_depth},
                            {"domain_pixels", info.domain_pixels()},
                            {"index_rebuilt", reader->index_rebuilt()},
                            {"decode_fps", decode_seconds > 0 ? n / decode_seconds : 0.0}}},
                          {"frames", frames}};
  if (!reference_files.empty()) {
    stats["reference"] = args.reference;
    stats["summary"]["psnr_db"] = psnr_json(point_total.psnr_db(info.box_diagonal_mm()));
    stats["summary"]["rms_mm"] = point_total.rms_mm;
    stats["summary"]["max_mm"] = point_total.max_mm;
    stats["summary"].update(surface_error_json(surface_total));
  }
  throw_if_error(write_json(std::filesystem::path(args.output) / "stats.json", stats));
  std::printf("%s: %lld frames decoded into %s (%.1f frames/s)\n", args.input.c_str(),
              static_cast<long long>(reader->frame_count() - failed), args.output.c_str(),
              decode_seconds > 0 ? n / decode_seconds : 0.0);
  if (!reference_files.empty())
    std::printf(
        "against %s: PSNR %.2f dB, max %.4g mm, normal error mean %.2f / p95 %.2f / max %.1f "
        "deg, Hausdorff %.4g mm (outline %.4g mm)\n",
        args.reference.c_str(), point_total.psnr_db(info.box_diagonal_mm()), point_total.max_mm,
        surface_total.normal_mean_deg(), surface_total.normal_p95_deg(),
        surface_total.normal_max_deg, surface_total.hausdorff_mm,
        surface_total.outline_hausdorff_mm);
  if (failed)
    throw CommandFailed(corrupt_data(std::to_string(failed) + " of " +
                                     std::to_string(reader->frame_count()) +
                                     " frames could not be decoded; first: " + first_error));
}

}  // namespace

void add_decode_command(CLI::App& app) {
  auto args = std::make_shared<DecodeArgs>();
  auto* cmd = app.add_subcommand("decode", "Decode a .gvid stream into geometry-image EXRs");
  cmd->add_option("input", args->input, "Input .gvid file")->required();
  cmd->add_option("-o,--output", args->output, "Output folder")->required();
  cmd->add_option("--reference", args->reference,
                  "Folder of the encoder's input frame_NNNNNN.exr: also report each frame's "
                  "point error and surface error (normal-angle error, Hausdorff distance)");
  cmd->add_option("--threads", args->threads,
                  "Threads writing and measuring decoded frames, 1..16, or 0: the hardware "
                  "threads, at most 16 (frames are decoded in order; the files do not depend on "
                  "it)")
      ->capture_default_str();
  cmd->add_option("--exr-compression", args->exr_compression, kExrCompressionHelp)
      ->capture_default_str();
  cmd->callback([args] { run_decode(*args); });
}

}  // namespace gvkit::tools
