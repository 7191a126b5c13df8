// gvkit encode GV_DIR -o FILE.gvid: compresses a folder of geometry-image EXRs
// (frame_NNNNNN.exr) into a .gvid stream, and writes FILE.gvid.stats.json beside it.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/surface_metrics.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/log.hpp"
#include "gvkit/core/progress.hpp"
#include "surface_error_json.hpp"

namespace gvkit::tools {
namespace {
namespace fs = std::filesystem;

struct EncodeArgs {
  std::string input, output, preset = "slow", value_prediction = "none", resolution = "auto";
  std::vector<int> plane_qp_offsets;
  codec::EncoderOptions options;
  double fps = 30.0;
  bool no_gv_modes = false, no_td = false, no_decimation = false;
  bool qp_given = false;  // --qp on the command line
};

const char* const kPlaneNames[4] = {"X", "Y", "Z", "T"};

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
  options.geometry_modes = !args.no_gv_modes;
  options.td_prediction = !args.no_td;
  options.inter_decimation = !args.no_decimation;
  options.preset = value_or_throw(codec::parse_preset(args.preset));
  options.value_prediction = value_or_throw(codec::parse_value_prediction(args.value_prediction));
  options.resolution = value_or_throw(codec::parse_resolution(args.resolution));
  if (!args.plane_qp_offsets.empty()) {
    if (args.plane_qp_offsets.size() != 3)
      throw CommandFailed(invalid_argument("--plane-qp-offsets: give three values (X Y Z)"));
    for (int i = 0; i < 3; ++i) options.plane_qp_offset[i] = args.plane_qp_offsets[i];
  }
  throw_if_error(options.check());
  const auto files = value_or_throw(list_frame_files(args.input, ".exr"));
  if (files.empty()) throw CommandFailed(not_found(args.input + ": no frame_NNNNNN.exr files"));
  std::vector<GeometryImage> frames;
  {
    Progress progress("reading " + args.input, static_cast<int64_t>(files.size()));
    for (const auto& f : files) {
      frames.push_back(value_or_throw(read_geometry_image_exr(f.path)));
      progress.advance();
    }
    progress.finish();
  }
  const codec::SequenceInfo info =
      value_or_throw(codec::make_sequence_info(frames, options.bit_depth, args.fps));
  auto writer = value_or_throw(codec::GvidWriter::create(args.output, info, options));
  const double peak = info.box_diagonal_mm();
  const double vertices = static_cast<double>(info.domain_pixels());
  nlohmann::json per_frame = nlohmann::json::array();
  codec::GeometryError total;
  codec::SurfaceError surface_total;
  Progress progress("encoding", static_cast<int64_t>(frames.size()));
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  // The writer returns the reconstructions of the frames it completes, in display order (with B
  // frames, a frame waits for the anchor after it; finish() codes the rest).
  size_t reported = 0;
  const auto report = [&](const GeometryImage& recon) {
    const size_t i = reported++;
    const codec::GeometryError e = codec::geometry_error(frames[i], recon);
    codec::accumulate(total, e);
    const codec::SurfaceError surface = codec::surface_error(frames[i], recon);
    codec::accumulate(surface_total, surface);
    const int64_t bytes = writer->frame_bytes()[i];
    per_frame.push_back({{"frame", i},
                         {"source", files[i].path.filename().string()},
                         {"bytes", bytes},
                         {"bits_per_vertex", bytes * 8.0 / vertices},
                         {"psnr_db", e.psnr_db(peak)},
                         {"rms_mm", e.rms_mm},
                         {"max_mm", e.max_mm},
                         {"qp", writer->frame_qp()[i]},
                         {"type", codec::format::frame_type_name(writer->frame_types()[i])}});
    per_frame.back().update(surface_error_json(surface));
    if (const auto* q = writer->quality_controller())
      per_frame.back()["encodes"] = q->frame_encodes()[i];
    nlohmann::json syntax_bits;
    const codec::FrameCodingStats& fs = writer->frame_stats()[i];
    for (size_t p = 0; p < fs.planes.size(); ++p)
      syntax_bits[kPlaneNames[p]] = plane_stats_json(fs.planes[p]);
    per_frame.back()["syntax_bits"] = syntax_bits;
    progress.advance();
  };
  for (const GeometryImage& frame : frames)
    for (const GeometryImage& recon : value_or_throw(writer->write(frame))) report(recon);
  for (const GeometryImage& recon : value_or_throw(writer->finish())) report(recon);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Process CPU time (all threads) of the encoding loop: comparable on a loaded machine.
  const double cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  progress.finish();
  int64_t total_bytes = writer->header_bytes();
  for (int64_t b : writer->frame_bytes()) total_bytes += b;
  const double n = static_cast<double>(frames.size());
  const double bpv = (total_bytes - writer->header_bytes()) * 8.0 / vertices / n;
  const double psnr = total.psnr_db(peak);
  nlohmann::json stats = {
      {"input", args.input},
      {"output", args.output},
      {"options",
       {{"qp", options.qp},
        {"lossless", options.lossless},
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
        {"max_transform", options.max_transform},
        {"cross_plane", options.cross_plane},
        {"cross_plane_contexts", options.cross_plane_contexts},
        {"partitions", options.partitions},
        {"deblocking", options.deblocking},
        {"temporal_contexts", options.temporal_contexts},
        {"compact_segments", options.compact_segments},
        {"compact_packets", options.compact_packets},
        {"merge", options.merge},
        {"td16", options.td16},
        {"quadratic_intra", options.quadratic_intra},
        {"resolution", codec::resolution_name(options.resolution)},
        {"value_prediction", codec::value_prediction_name(options.value_prediction)},
        {"plane_qp_offsets",
         {options.plane_qp_offset[0], options.plane_qp_offset[1], options.plane_qp_offset[2]}},
        {"p_qp_offset", options.p_qp_offset},
        {"bframes", options.b_frames()},
        {"b_qp_offset", options.b_qp_offset},
        {"bitrate_kbps", options.bitrate_kbps},
        {"buffer_seconds", options.buffer_seconds},
        {"target_psnr_db", options.target_psnr_db},
        {"target_rms_mm", options.target_rms_mm},
        {"intra_target_offset_db", options.intra_target_offset_db},
        {"refs", options.reference_frames()},
        {"outline_weight", options.outline_weight},
        {"threads", options.threads},
        {"fps", args.fps}}},
      {"summary",
       {{"frames", frames.size()},
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
  stats["summary"].update(surface_error_json(surface_total));
  if (const auto* q = writer->quality_controller()) {
    stats["summary"]["encodes_per_frame"] = q->total_encodes() / n;
    stats["summary"]["frames_missing_target"] = q->frames_missed();
  }
  for (auto& f : stats["frames"])
    if (!std::isfinite(f["psnr_db"].get<double>())) f["psnr_db"] = "inf";
  throw_if_error(write_json(args.output + ".stats.json", stats));
  std::printf(
      "%s: %zu frames %dx%d, %lld bytes, %.4f bits/vertex/frame, PSNR %.2f dB, max %.4g mm, "
      "normal error mean %.2f / p95 %.2f / max %.1f deg, Hausdorff %.4g mm (outline %.4g mm), "
      "%.1f frames/s (%.1f per CPU second)\n",
      args.output.c_str(), frames.size(), info.width, info.height,
      static_cast<long long>(total_bytes), bpv, psnr, total.max_mm, surface_total.normal_mean_deg(),
      surface_total.normal_p95_deg(), surface_total.normal_max_deg, surface_total.hausdorff_mm,
      surface_total.outline_hausdorff_mm, n / seconds, n / cpu_seconds);
}

}  // namespace

void add_encode_command(CLI::App& app) {
  auto args = std::make_shared<EncodeArgs>();
  auto* cmd = app.add_subcommand(
      "encode", "Compress a folder of geometry-image EXRs (frame_NNNNNN.exr) into a .gvid stream");
  cmd->add_option("input", args->input, "Folder of frame_NNNNNN.exr geometry images")->required();
  cmd->add_option("-o,--output", args->output, "Output .gvid file")->required();
  auto* qp = cmd->add_option("--qp", args->options.qp,
                             "Quantization parameter, -6(B-8)..51 (lower = finer)");
  auto* lossless =
      cmd->add_flag("--lossless", args->options.lossless, "Lossless (transform bypass)");
  qp->excludes(lossless);
  cmd->add_option("--bit-depth", args->options.bit_depth, "Bits per xyz sample, 8..16");
  cmd->add_flag("--no-gv-modes", args->no_gv_modes, "Disable the four geometry intra modes");
  cmd->add_flag("--no-td", args->no_td,
                "P frames: disable temporal-difference prediction (inter + intra-predicted "
                "difference)");
  cmd->add_flag("--intra-only", args->options.intra_only, "Intra frames only (no P frames)");
  cmd->add_option("--intra-period,--gop", args->options.intra_period,
                  "Frames from one intra frame to the next (P frames between); default 30");
  cmd->add_option("--search-range", args->options.search_range,
                  "Motion search range of P frames in samples, 0..32");
  cmd->add_option("--subpel", args->options.subpel,
                  "Motion vector precision of P frames: 0 (whole samples), 2 (half) or 4 "
                  "(quarter, default; H.264 interpolation)");
  cmd->add_flag("--shared-motion", args->options.shared_motion,
                "P frames: let each Y and Z macroblock take over the X plane's vector with one "
                "flag (format 1.4; pays in lossless coding); without it the Y and Z planes code "
                "their own motion (1.3 syntax)");
  cmd->add_option(
      "--max-transform", args->options.max_transform,
      "Largest residual transform of inter and I16x16 macroblocks in lossy frames: 4 "
      "(4x4 only), 8 or 16 (8x8 / 16x16 chosen per macroblock; format 1.6; default 16)");
  cmd->add_flag("--joint-motion-search", args->options.joint_motion_search,
                "P frames with shared motion: search the X plane's vectors on the error of all "
                "three planes (always on in lossless and near-lossless frames)");
  cmd->add_flag("--no-decimation", args->no_decimation,
                "P frames: keep sparse +-1 inter residual blocks and the intra rounding (no "
                "inter dead zone)");
  cmd->add_flag("--rdoq,!--no-rdoq", args->options.rdoq,
                "Lossy frames: choose each block's levels by rate-distortion cost "
                "(rate-distortion optimised quantization; on by default, encoder only); "
                "--no-rdoq quantizes with fixed rounding offsets");
  cmd->add_flag("--skip-check", args->options.skip_check,
                "P frames: try the predicted vector first and take a skip found there at once "
                "(fast preset: about 2x faster encoding, slightly lower quality)");
  cmd->add_flag("--cross-plane,!--no-cross-plane", args->options.cross_plane,
                "Let each Y and Z macroblock add a scaled copy of the X plane's residual to its "
                "own (cross-plane residual prediction, format 1.6; on by default); "
                "--no-cross-plane writes the 1.4 / 1.5 stream");
  cmd->add_flag("--cross-plane-contexts,!--no-cross-plane-contexts",
                args->options.cross_plane_contexts,
                "Start the Y and Z planes' CABAC contexts from the states the X plane's reached "
                "(cross-plane contexts, format 1.7); --no-cross-plane-contexts writes the 1.6 "
                "stream");
  cmd->add_flag("--partitions,!--no-partitions", args->options.partitions,
                "P frames, slow preset: let plain inter macroblocks split into 16x8, 8x16 or 8x8 "
                "partitions with their own reference and vector (inter partitions, format 1.7; "
                "on by default; the fast preset codes 16x16 only); --no-partitions writes the 1.6 "
                "stream");
  cmd->add_flag("--intra-rdo,!--no-intra-rdo", args->options.intra_rdo,
                "Fast preset, lossy I frames: decide macroblock types and modes by "
                "rate-distortion cost on a shortlist of the cheapest modes by SATD (on by "
                "default; the slow preset decides every frame so); the stream syntax is the same");
  cmd->add_flag("--deblock,!--no-deblock", args->options.deblocking,
                "Lossy frames: filter the 8x8 block edges of every reconstructed plane in the "
                "loop (deblocking filter, format 1.8; on by default); --no-deblock writes the "
                "1.7 stream");
  cmd->add_flag("--temporal-contexts,!--no-temporal-contexts", args->options.temporal_contexts,
                "P and B frames: start every plane's CABAC contexts from the states the same "
                "plane of the reference frame ended with (temporal contexts, format 1.9; on by "
                "default); with --no-compact-segments too, --no-temporal-contexts writes the 1.8 "
                "stream");
  cmd->add_flag("--compact-segments,!--no-compact-segments", args->options.compact_segments,
                "Write each plane segment's size as a varint and none for the last segment "
                "(format 1.9; on by default); --no-compact-segments writes u32 sizes (the 1.8 "
                "payload)");
  cmd->add_flag("--compact-packets,!--no-compact-packets", args->options.compact_packets,
                "Write the compact packet header (13-21 bytes instead of 24) and end every plane "
                "segment with the fewest bytes (format 1.10; on by default); with the other 1.9 "
                "options --no-compact-packets writes the 1.9 stream");
  cmd->add_flag("--merge,!--no-merge", args->options.merge,
                "P frames: a skip or 16x16 inter macroblock may take one of up to four "
                "neighbours' vectors, coding which in one to four bins (format 1.11; on by "
                "default); --no-merge writes the 1.10 stream");
  cmd->add_flag("--td16,!--no-td16", args->options.td16,
                "P frames: a temporal-difference macroblock may predict the difference with one "
                "16x16 mode, its residual then with any transform size (format 1.12; on by "
                "default); --no-td16 writes the 1.11 stream");
  cmd->add_flag("--quadratic-intra,!--no-quadratic-intra", args->options.quadratic_intra,
                "I16x16 macroblocks may predict with a least-squares quadratic surface through "
                "the two rows above and the two columns left of them (format 1.13; on by "
                "default); --no-quadratic-intra writes the 1.12 stream");
  cmd->add_option("--resolution", args->resolution,
                  "full, half or auto: code lossy frames at half resolution, upsampled 2x by the "
                  "decoder (format 1.14); auto (default) decides per I frame: half where halving "
                  "loses less than coding at full resolution; full writes the 1.13 stream");
  cmd->add_option("--preset", args->preset, "fast (SATD decisions) or slow (RDO)");
  cmd->add_option("--fps", args->fps, "Frame rate stored in the stream");
  auto* max_error = cmd->add_option(
      "--max-error-mm", args->options.max_error_mm,
      "Near-lossless: guarantee a point error <= this (mm) on every pixel; 0 = off");
  max_error->excludes(lossless);
  max_error->excludes(qp);
  cmd->add_option("--value-prediction", args->value_prediction,
                  "P frames: none, offset, weighted (per plane) or affine (3D) map of the "
                  "reference's xyz");
  cmd->add_option("--plane-qp-offsets", args->plane_qp_offsets,
                  "QP offsets of the X, Y, Z planes, -12..12 each")
      ->expected(3);
  cmd->add_option("--p-qp-offset", args->options.p_qp_offset,
                  "Added to --qp in P frames, 0..12 (ignored under --bitrate)");
  cmd->add_option("--bframes", args->options.bframes,
                  "Consecutive B frames between two anchors (I or P frames), 0..3 (format 1.5; 0 "
                  "writes a 1.4 stream); default 1 in lossy, 0 in lossless and --max-error-mm "
                  "streams");
  cmd->add_option("--b-qp-offset", args->options.b_qp_offset,
                  "Added to the P frames' QP in B frames, 0..12 (under --bitrate: to the last P "
                  "frame's)");
  cmd->add_option("--bitrate", args->options.bitrate_kbps,
                  "Target bitrate in kbit/s (rate control; --qp is the starting QP); 0 = constant "
                  "QP");
  cmd->add_option("--buffer-seconds", args->options.buffer_seconds,
                  "Rate-control buffer in seconds of the target bitrate, 0.1..100");
  cmd->add_option("--target-psnr", args->options.target_psnr_db,
                  "Constant quality: each frame at the coarsest QP whose geometry PSNR (dB) meets "
                  "this (2-4 encodes per frame; --qp is the starting QP); 0 = off");
  cmd->add_option("--target-rms-mm", args->options.target_rms_mm,
                  "Constant quality: each frame at the coarsest QP whose RMS point error (mm) "
                  "meets this; 0 = off");
  cmd->add_option("--intra-target-offset", args->options.intra_target_offset_db,
                  "Constant quality: I frames aim this many dB above the target (a finer "
                  "reference for the P frames), 0..20");
  cmd->add_option("--refs", args->options.refs,
                  "Reference frames of P frames, 1..5: each macroblock predicts from one of the "
                  "nearest anchors since the last I frame (format 1.6); 1 = one reference (a "
                  "1.4 / 1.5 stream); default 3 in lossy, 1 in lossless and --max-error-mm "
                  "streams");
  cmd->add_option("--outline-weight", args->options.outline_weight,
                  "Lossy frames: the outline's samples (the face's border, the rims of its holes) "
                  "count this many times in the encoder's rate-distortion decisions, 1..64 "
                  "(encoder only; default 8; 1 = plain SSD)");
  cmd->add_option("--threads", args->options.threads,
                  "Planes encoded in parallel, 1..16 (the stream does not depend on it)");
  cmd->callback([args, qp] {
    args->qp_given = qp->count() > 0;
    run_encode(*args);
  });
}

}  // namespace gvkit::tools
