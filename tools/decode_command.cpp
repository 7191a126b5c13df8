// gvkit decode FILE.gvid -o DIR: writes every decodable frame as DIR/frame_NNNNNN.exr and
// DIR/stats.json; a damaged frame is reported and skipped, and the command then fails.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/log.hpp"
#include "gvkit/core/progress.hpp"

namespace gvkit::tools {
namespace {

struct DecodeArgs {
  std::string input, output;
};

void run_decode(const DecodeArgs& args) {
  auto reader = value_or_throw(codec::GvidReader::open(args.input));
  throw_if_error(ensure_directory(args.output));
  if (reader->index_rebuilt())
    logger().warn(
        "{}: the seek index is missing or damaged (a cut or damaged file): {} frames found by a "
        "scan; frames after a cut are lost",
        args.input, reader->frame_count());
  const codec::SequenceInfo& info = reader->info();
  const double vertices = static_cast<double>(info.domain_pixels());
  nlohmann::json frames = nlohmann::json::array();
  int64_t failed = 0;
  std::string first_error;
  double decode_seconds = 0;
  Progress progress("decoding", reader->frame_count());
  for (int64_t i = 0; i < reader->frame_count(); ++i) {
    const auto start = std::chrono::steady_clock::now();
    auto frame = reader->decode_frame(i);
    decode_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    nlohmann::json entry = {{"frame", i},
                            {"bits", reader->frame_bits(i)},
                            {"bits_per_vertex", reader->frame_bits(i) / vertices}};
    if (frame.is_ok()) {
      throw_if_error(write_geometry_image_exr(frame_path(args.output, i, ".exr"), *frame));
      entry["status"] = "ok";
    } else {
      ++failed;
      if (first_error.empty()) first_error = frame.status().message();
      logger().warn("{}", frame.status().message());
      entry["status"] = frame.status().message();
    }
    frames.push_back(entry);
    progress.advance();
  }
  progress.finish();
  const double n = static_cast<double>(reader->frame_count());
  nlohmann::json stats = {{"input", args.input},
                          {"output", args.output},
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
  throw_if_error(write_json(std::filesystem::path(args.output) / "stats.json", stats));
  std::printf("%s: %lld frames decoded into %s (%.1f frames/s)\n", args.input.c_str(),
              static_cast<long long>(reader->frame_count() - failed), args.output.c_str(),
              decode_seconds > 0 ? n / decode_seconds : 0.0);
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
  cmd->callback([args] { run_decode(*args); });
}

}  // namespace gvkit::tools
