// gvkit encode GV_DIR -o FILE.gvid: compresses a folder of geometry-image EXRs
// (frame_NNNNNN.exr) into a .gvid stream, and writes FILE.gvid.stats.json beside it.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/parallel_pipeline.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gvkit/codec/encoder_tune.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/gvid_writer.hpp"
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
namespace fs = std::filesystem;

struct EncodeArgs {
  std::string input, output, preset = "slow", profile = "auto";
  std::vector<std::string> tunes;  // key=value each (encoder_tune.hpp)
  codec::EncoderOptions options;
  double fps = 30.0;
  bool qp_given = false;          // --qp on the command line
  int64_t frame_cache_mb = 1024;  // --frame-cache-mb
  std::string measures = "full";  // --measures: full | points
};

// `--tune help`: the keys, their values and what they change (to stdout).
void print_tune_keys() {
  std::printf("gvkit encode --tune key=value (repeatable; for experiments, docs/encoding.md):\n");
  for (const codec::TuneKey& k : codec::tune_keys())
    std::printf("  %-22s %-28s %s\n", k.name, k.values, k.help);
}

const char* const kPlaneNames[4] = {"X", "Y", "Z", "T"};

// Bytes of a frame's pixel arrays (what keeping it in memory costs).
int64_t frame_bytes(const GeometryImage& f) {
  int64_t bytes = 0;
  for (const cv::Mat* m : {&f.xyz_mm, &f.texture, &f.domain_mask})
    bytes += static_cast<int64_t>(m->total() * m->elemSize());
  return bytes;
}

nlohmann::json plane_stats_json(const codec::PlaneCodingStats& s) {
  nlohmann::json j;
  for (int g = 0; g < codec::kSyntaxGroupCount; ++g) j[codec::syntax_group_name(g)] = s.bits[g];
  j["total"] = s.total_bits();
  j["intra_mbs"] = s.intra_mbs;
  j["inter_mbs"] = s.inter_mbs;
  j["td_mbs"] = s.td_mbs;
  j["td16_mbs"] = s.td16_mbs;
  j["quadratic_mbs"] = s.quadratic_mbs;
  j["skip_mbs"] = s.skip_mbs;
  j["merge_skip_mbs"] = s.merge_skip_mbs;
  j["merged_mbs"] = s.merged_mbs;
  int64_t cross = 0;
  for (int64_t n : s.cross_scale_mbs) cross += n;
  if (cross > 0) {  // format 1.6: macroblocks per cross-plane scale -8, -4, .., 8
    j["cross_scale_mbs"] = nlohmann::json::array();
    for (int64_t n : s.cross_scale_mbs) j["cross_scale_mbs"].push_back(n);
  }
  if (s.partition_mbs[1] + s.partition_mbs[2] + s.partition_mbs[3] > 0) {
    // Format 1.7: plain inter macroblocks per partition type 16x16, 16x8, 8x16, 8x8.
    j["partition_mbs"] = nlohmann::json::array();
    for (int64_t n : s.partition_mbs) j["partition_mbs"].push_back(n);
  }
  return j;
}

// Bits per syntax element group, summed per frame type and plane ("I" / "P" / "B" -> "X" / ...),
// in JSON and (with --verbose) as a table on the log.
nlohmann::json bit_accounting(const std::vector<codec::FrameCodingStats>& frames, double vertices) {
  nlohmann::json out = nlohmann::json::object();
  for (const char* type : {"I", "P", "B"}) {
    std::vector<codec::PlaneCodingStats> sum;
    int count = 0;
    for (const auto& f : frames) {
      if (*(f.intra ? "I" : (f.bidirectional ? "B" : "P")) != *type) continue;
      ++count;
      sum.resize(std::max(sum.size(), f.planes.size()));
      for (size_t p = 0; p < f.planes.size(); ++p) sum[p] += f.planes[p];
    }
    if (!count) continue;
    nlohmann::json j = {{"frames", count}};
    codec::PlaneCodingStats all;
    for (size_t p = 0; p < sum.size(); ++p) {
      j[kPlaneNames[p]] = plane_stats_json(sum[p]);
      all += sum[p];
    }
    j["all"] = plane_stats_json(all);
    out[type] = j;
    for (size_t p = 0; p <= sum.size(); ++p) {
      const codec::PlaneCodingStats& s = p < sum.size() ? sum[p] : all;
      std::string line =
          fmt::format("{} frames ({}), plane {:>3}: {:8.4f} bits/vertex/frame =", type, count,
                      p < sum.size() ? kPlaneNames[p] : "all", s.total_bits() / vertices / count);
      for (int g = 0; g < codec::kSyntaxGroupCount; ++g)
        line += fmt::format(" {} {:.1f} %", codec::syntax_group_name(g),
                            100.0 * s.bits[g] / std::max(1.0, s.total_bits()));
      line += fmt::format("; macroblocks intra {} inter {} td {} skip {}", s.intra_mbs, s.inter_mbs,
                          s.td_mbs, s.skip_mbs);
      logger().debug("{}", line);
    }
  }
  return out;
}

void run_encode(const EncodeArgs& args) {
  codec::EncoderOptions options = args.options;
  // The default QP is for 16-bit samples; a bit depth without that QP takes its finest one.
  const int qp_min = -6 * (options.bit_depth - 8);
  if (!args.qp_given && options.qp < qp_min) {
    logger().info("--bit-depth {}: QP {} (the finest at that depth) instead of the default {}",
                  options.bit_depth, qp_min, options.qp);
    options.qp = qp_min;
  }
  options.threads = command_threads(options.threads, 16);
  options.preset = value_or_throw(codec::parse_preset(args.preset));
  options.profile = value_or_throw(codec::parse_profile(args.profile));
  for (const std::string& tune : args.tunes) throw_if_error(codec::apply_tune(tune, &options));
  throw_if_error(options.check());
  const auto files = value_or_throw(list_frame_files(args.input, ".exr"));
  if (files.empty()) throw CommandFailed(not_found(args.input + ": no frame_NNNNNN.exr files"));
  const size_t frame_count = files.size();
  const size_t tokens = 2 * static_cast<size_t>(options.threads);
  tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism,
                                  static_cast<size_t>(options.threads));
  // A frame read on a worker, or why it could not be: the failure is raised by the serial stage
  // that takes the frames in order, so the first failing file in frame order is the one named,
  // whatever the threads did.
  struct Input {
    size_t index = 0;
    std::shared_ptr<const GeometryImage> frame;
    Status status = Status::ok();
  };
  const auto read_input = [&](size_t i) {
    Input in;
    in.index = i;
    Result<GeometryImage> frame = read_geometry_image_exr(files[i].path);
    if (frame.is_ok())
      in.frame = std::make_shared<const GeometryImage>(std::move(frame).value());
    else
      in.status = frame.status();
    return in;
  };
  // First pass: every frame read (each EXR decompressed on --threads threads) and checked in frame
  // order for the sequence's quantization box and domain mask. The first frames are kept for the
  // encoding while they fit --frame-cache-mb; the others are read again then, so memory does not
  // grow with the length of the video.
  const int64_t cache_budget = args.frame_cache_mb << 20;
  int64_t cached_bytes = 0;
  std::vector<std::shared_ptr<const GeometryImage>> cached(frame_count);
  codec::SequenceInfoBuilder builder(options.bit_depth, args.fps);
  {
    Progress progress("reading " + args.input, static_cast<int64_t>(frame_count));
    size_t next = 0;
    bool caching = true;
    tbb::parallel_pipeline(
        tokens,
        tbb::make_filter<void, size_t>(tbb::filter_mode::serial_in_order,
                                       [&](tbb::flow_control& control) {
                                         if (next == frame_count) control.stop();
                                         return next++;
                                       }) &
            tbb::make_filter<size_t, Input>(tbb::filter_mode::parallel, read_input) &
            tbb::make_filter<Input, void>(tbb::filter_mode::serial_in_order, [&](Input in) {
              throw_if_error(in.status);
              throw_if_error(builder.add(*in.frame).with_context(files[in.index].path.string()));
              const int64_t bytes = frame_bytes(*in.frame);
              caching = caching && cached_bytes + bytes <= cache_budget;
              if (caching) {
                cached[in.index] = std::move(in.frame);
                cached_bytes += bytes;
              }
              progress.advance();
            }));
    progress.finish();
  }
  const codec::SequenceInfo info = value_or_throw(builder.finish());
  const size_t cached_frames = static_cast<size_t>(
      std::count_if(cached.begin(), cached.end(), [](const auto& f) { return f != nullptr; }));
  if (cached_frames < frame_count)
    logger().info(
        "{} of {} frames kept in memory ({} MiB, --frame-cache-mb {}); the rest are read "
        "again while encoding",
        cached_frames, frame_count, cached_bytes >> 20, args.frame_cache_mb);
  auto writer = value_or_throw(codec::GvidWriter::create(args.output, info, options));
  const double peak = info.box_diagonal_mm();
  const double vertices = static_cast<double>(info.domain_pixels());
  nlohmann::json per_frame = nlohmann::json::array();
  codec::GeometryError total;
  codec::SurfaceError surface_total;
  Progress progress("encoding", static_cast<int64_t>(frame_count));
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  // Second pass, a TBB pipeline within --threads threads: frames are taken from the cache or read
  // again (on workers) -> coded in order -> measured in parallel -> reported in order. The writer
  // returns the reconstructions of the frames it completes, in display order (with B frames, a
  // frame waits for the anchor after it; finish() codes the rest); each one's point and surface
  // errors against its input are measured on a worker while the encoder goes on with the next
  // frames. What a frame reports is taken from the writer when the frame completes. An input is
  // released once its reconstruction is measured.
  struct Completed {
    size_t index = 0;
    std::shared_ptr<const GeometryImage> input;
    GeometryImage recon;
    int64_t bytes = 0;
    int qp = 0;
    codec::format::FrameType type = codec::format::FrameType::kIntra;
    codec::FrameCodingStats stats;
    int encodes = -1;  // the quality controller's encodes of the frame (-1: none)
    codec::GeometryError error;
    codec::SurfaceError surface;
  };
  using CompletedFrames = std::vector<std::shared_ptr<Completed>>;
  std::map<size_t, std::shared_ptr<const GeometryImage>> waiting;  // coded inputs, not completed
  size_t next_input = 0, next_output = 0;
  const auto take_input = [&](size_t i) {
    if (i == frame_count) return Input{i, nullptr, Status::ok()};  // the token of finish()
    if (cached[i]) {
      Input in{i, std::move(cached[i]), Status::ok()};
      cached[i] = nullptr;
      return in;
    }
    Input in = read_input(i);
    if (in.status.is_ok()) {
      const Status fits = codec::check_frame_fits(info, *in.frame);
      if (!fits.is_ok())
        in.status = invalid_argument(files[i].path.string() +
                                     ": changed since it was first read: " + fits.message());
    }
    return in;
  };
  const auto code = [&](Input in) {
    throw_if_error(in.status);
    std::vector<GeometryImage> done;
    if (in.index < frame_count) {
      done = value_or_throw(writer->write(*in.frame));
      waiting[in.index] = std::move(in.frame);
    } else {
      done = value_or_throw(writer->finish());
    }
    CompletedFrames out;
    for (GeometryImage& recon : done) {
      auto c = std::make_shared<Completed>();
      c->index = next_output++;
      c->input = std::move(waiting.at(c->index));
      waiting.erase(c->index);
      c->recon = std::move(recon);
      c->bytes = writer->frame_bytes()[c->index];
      c->qp = writer->frame_qp()[c->index];
      c->type = writer->frame_types()[c->index];
      c->stats = writer->frame_stats()[c->index];
      if (const auto* q = writer->quality_controller()) c->encodes = q->frame_encodes()[c->index];
      out.push_back(std::move(c));
    }
    return out;
  };
  const bool surface_measures = args.measures == "full";
  const auto measure = [&](CompletedFrames frames) {
    for (const auto& c : frames) {
      c->error = codec::geometry_error(*c->input, c->recon);
      if (surface_measures) c->surface = codec::surface_error(*c->input, c->recon);
      c->input = nullptr;  // measured: the memory of both goes back now
      c->recon = GeometryImage();
    }
    return frames;
  };
  const auto report = [&](const std::shared_ptr<Completed>& c) {
    const size_t i = c->index;
    const codec::GeometryError& e = c->error;
    codec::accumulate(total, e);
    codec::accumulate(surface_total, c->surface);
    per_frame.push_back({{"frame", i},
                         {"source", files[i].path.filename().string()},
                         {"bytes", c->bytes},
                         {"bits_per_vertex", c->bytes * 8.0 / vertices},
                         {"psnr_db", e.psnr_db(peak)},
                         {"rms_mm", e.rms_mm},
                         {"max_mm", e.max_mm},
                         {"qp", c->qp},
                         {"type", codec::format::frame_type_name(c->type)}});
    if (surface_measures) per_frame.back().update(surface_error_json(c->surface));
    if (c->encodes >= 0) per_frame.back()["encodes"] = c->encodes;
    nlohmann::json syntax_bits;
    for (size_t p = 0; p < c->stats.planes.size(); ++p)
      syntax_bits[kPlaneNames[p]] = plane_stats_json(c->stats.planes[p]);
    per_frame.back()["syntax_bits"] = syntax_bits;
    progress.advance();
  };
  tbb::parallel_pipeline(
      tokens,
      tbb::make_filter<void, size_t>(tbb::filter_mode::serial_in_order,
                                     [&](tbb::flow_control& control) {
                                       if (next_input > frame_count) control.stop();
                                       return next_input++;
                                     }) &
          tbb::make_filter<size_t, Input>(tbb::filter_mode::parallel, take_input) &
          tbb::make_filter<Input, CompletedFrames>(tbb::filter_mode::serial_in_order, code) &
          tbb::make_filter<CompletedFrames, CompletedFrames>(tbb::filter_mode::parallel, measure) &
          tbb::make_filter<CompletedFrames, void>(tbb::filter_mode::serial_in_order,
                                                  [&](const CompletedFrames& frames) {
                                                    for (const auto& c : frames) report(c);
                                                  }));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Process CPU time (all threads) of the encoding loop: comparable on a loaded machine.
  const double cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  progress.finish();
  int64_t total_bytes = writer->header_bytes();
  for (int64_t b : writer->frame_bytes()) total_bytes += b;
  const double n = static_cast<double>(frame_count);
  const double bpv = (total_bytes - writer->header_bytes()) * 8.0 / vertices / n;
  const double psnr = total.psnr_db(peak);
  nlohmann::json stats = {
      {"input", args.input},
      {"output", args.output},
      {"format", std::to_string(codec::format::kMajorVersion) + "." +
                     std::to_string(codec::format::kMinorVersion)},
      {"profile", codec::profile_name(options.resolved_profile())},
      {"options",
       {{"qp", options.qp},
        {"lossless", options.lossless},
        {"profile", codec::profile_name(options.profile)},
        {"bit_depth", options.bit_depth},
        {"geometry_modes", options.geometry_modes},
        {"intra_only", options.intra_only},
        {"intra_period", options.intra_period},
        {"search_range", options.search_range},
        {"preset", codec::preset_name(options.preset)},
        {"max_error_mm", options.max_error_mm},
        {"td_prediction", options.td_prediction},
        {"subpel", options.subpel},
        {"shared_motion", options.shared_motion},
        {"joint_motion_search", options.joint_motion_search},
        {"inter_decimation", options.inter_decimation},
        {"rdoq", options.rdoq},
        {"intra_rdo", options.intra_rdo},
        {"skip_check", options.skip_check},
        {"td_whole_retry", options.td_whole_retry},
        {"max_transform", options.max_transform},
        {"cross_plane", options.cross_plane},
        {"cross_plane_contexts", options.cross_plane_contexts},
        {"partitions", options.partitions},
        {"deblocking", options.deblocking},
        {"temporal_contexts", options.temporal_contexts},
        {"merge", options.merge},
        {"td16", options.td16},
        {"quadratic_intra", options.quadratic_intra},
        {"resolution", codec::resolution_name(options.resolution)},
        {"value_prediction", codec::value_prediction_name(options.value_prediction)},
        {"plane_qp_offsets",
         {options.plane_qp_offset[0], options.plane_qp_offset[1], options.plane_qp_offset[2]}},
        {"p_qp_offset", options.p_qp_offset},
        {"deblock_beta", options.deblock.beta},
        {"deblock_tc", options.deblock.tc},
        {"bframes", options.b_frames()},
        {"b_qp_offset", options.b_qp_offset},
        {"bitrate_kbps", options.bitrate_kbps},
        {"buffer_seconds", options.buffer_seconds},
        {"target_psnr_db", options.target_psnr_db},
        {"target_rms_mm", options.target_rms_mm},
        {"intra_target_offset_db", options.intra_target_offset_db},
        {"refs", options.reference_frames()},
        {"outline_weight", options.outline_weight},
        {"texture_qp", options.texture_qp},
        {"threads", options.threads},
        {"frame_cache_mb", args.frame_cache_mb},
        {"measures", args.measures},
        {"fps", args.fps}}},
      {"summary",
       {{"frames", frame_count},
        {"width", info.width},
        {"height", info.height},
        {"domain_pixels", info.domain_pixels()},
        {"box_diagonal_mm", peak},
        {"step_mm", info.step_mm()},
        {"file_bytes", total_bytes},
        {"bits_per_vertex_per_frame", bpv},
        {"kbit_per_s", (total_bytes - writer->header_bytes()) * 8.0 / n * args.fps / 1000.0},
        {"psnr_db", std::isfinite(psnr) ? nlohmann::json(psnr) : nlohmann::json("inf")},
        {"rms_mm", total.rms_mm},
        {"max_mm", total.max_mm},
        {"encode_fps", n / seconds},
        {"encode_cpu_seconds", cpu_seconds},
        {"encode_fps_cpu", n / cpu_seconds},
        {"max_buffer_fullness_bits",
         writer->rate_controller() ? writer->rate_controller()->max_fullness_bits() : 0.0},
        {"buffer_bits", writer->rate_controller() ? writer->rate_controller()->buffer_bits() : 0.0},
        {"syntax_bits", bit_accounting(writer->frame_stats(), vertices)}}},
      {"frames", per_frame}};
  if (surface_measures) stats["summary"].update(surface_error_json(surface_total));
  if (const auto* q = writer->quality_controller()) {
    stats["summary"]["encodes_per_frame"] = q->total_encodes() / n;
    stats["summary"]["frames_missing_target"] = q->frames_missed();
  }
  for (auto& f : stats["frames"])
    if (!std::isfinite(f["psnr_db"].get<double>())) f["psnr_db"] = "inf";
  throw_if_error(write_json(args.output + ".stats.json", stats));
  std::string surface_text;
  if (surface_measures)
    surface_text = fmt::format(
        ", normal error mean {:.2f} / p95 {:.2f} / max {:.1f} deg, Hausdorff {:.4g} mm (outline "
        "{:.4g} mm)",
        surface_total.normal_mean_deg(), surface_total.normal_p95_deg(),
        surface_total.normal_max_deg, surface_total.hausdorff_mm,
        surface_total.outline_hausdorff_mm);
  std::printf(
      "%s: %zu frames %dx%d, %lld bytes, %.4f bits/vertex/frame, PSNR %.2f dB, max %.4g mm%s, "
      "%.1f frames/s (%.1f per CPU second)\n",
      args.output.c_str(), frame_count, info.width, info.height,
      static_cast<long long>(total_bytes), bpv, psnr, total.max_mm, surface_text.c_str(),
      n / seconds, n / cpu_seconds);
}

}  // namespace

void add_encode_command(CLI::App& app) {
  auto args = std::make_shared<EncodeArgs>();
  args->options.threads = 0;  // automatic (run_encode)
  auto* cmd = app.add_subcommand(
      "encode",
      "Compress a folder of geometry-image EXRs (frame_NNNNNN.exr) into a .gvid stream (format "
      "2.0); writes OUT.stats.json beside it");
  cmd->add_option("input", args->input, "Folder of frame_NNNNNN.exr geometry images")->required();
  cmd->add_option("-o,--output", args->output, "Output .gvid file")->required();
  // The rate mode: one of these (default: --qp -10).
  auto* quality = cmd->add_option("--quality", args->options.target_psnr_db,
                                  "Constant quality: each frame at the coarsest QP whose geometry "
                                  "PSNR (dB, peak = the box diagonal) meets this; 2-4 encodes per "
                                  "frame");
  auto* qp = cmd->add_option(
      "--qp", args->options.qp,
      "Constant QP, -6(B-8)..51 (lower = finer; default -10: normal error p95 <= 2 deg on "
      "the main-job face); with "
      "--quality or --bitrate the starting QP");
  auto* bitrate = cmd->add_option("--bitrate", args->options.bitrate_kbps,
                                  "Target bitrate in kbit/s at --fps (rate control)");
  auto* max_error = cmd->add_option(
      "--max-error-mm", args->options.max_error_mm,
      "Near-lossless: every point within this error (mm) of the input (profile lossless)");
  auto* lossless = cmd->add_flag("--lossless", args->options.lossless,
                                 "Lossless: decoded samples equal the quantized input (profile "
                                 "lossless)");
  quality->excludes(bitrate);
  for (auto* exact : {max_error, lossless}) {
    exact->excludes(quality);
    exact->excludes(bitrate);
    exact->excludes(qp);
  }
  max_error->excludes(lossless);
  cmd->add_option("--preset", args->preset,
                  "fast (SATD decisions, several times faster) or slow (rate-distortion "
                  "optimised, the default)");
  cmd->add_option("--profile", args->profile,
                  "auto (default: lossless, intra or main from the options), lossless (every "
                  "frame lossless, or within --max-error-mm), intra (I frames only) or main");
  cmd->add_option("--intra-period,--gop", args->options.intra_period,
                  "Frames from one I frame to the next (P and B frames between); default 30");
  cmd->add_flag("--intra-only", args->options.intra_only, "I frames only (profile intra)");
  cmd->add_option("--bit-depth", args->options.bit_depth, "Bits per xyz sample, 8..16 (16)");
  cmd->add_option("--fps", args->fps, "Frame rate stored in the stream (30)");
  cmd->add_option(
         "--threads", args->options.threads,
         "Threads for reading, planes, B frames and the frames' error measures, 1..16, or 0: "
         "the hardware threads, at most 16 (the stream does not depend on it)")
      ->capture_default_str();
  cmd->add_option("--frame-cache-mb", args->frame_cache_mb,
                  "Input frames kept in memory from the first reading (which finds the "
                  "quantization box) for the encoding, in MiB; the frames beyond it are read "
                  "again, so memory stays bounded however long the video (the stream does not "
                  "depend on it)")
      ->capture_default_str()
      ->check(CLI::Range(int64_t{0}, int64_t{1} << 40));
  cmd->add_option("--measures", args->measures,
                  "Per-frame measures of the decoded frames in stats.json: full (point error, "
                  "normal-angle error and Hausdorff distances) or points (the point error only: "
                  "PSNR, RMS and max error; with the fast preset about a third less CPU); the "
                  "stream does not depend on it")
      ->capture_default_str()
      ->check(CLI::IsMember({"full", "points"}));
  cmd->add_option("--tune", args->tunes,
                  "key=value: an encoder tool switch or fine setting, for experiments "
                  "(repeatable; '--tune help' lists the keys, docs/encoding.md explains them)")
      ->take_all()
      ->allow_extra_args(false)
      ->each([](const std::string& value) {
        if (value != "help") return;
        print_tune_keys();  // and nothing else (no input or output needed)
        throw CLI::Success();
      });
  cmd->callback([args, qp] {
    args->qp_given = qp->count() > 0;
    run_encode(*args);
  });
}

}  // namespace gvkit::tools
