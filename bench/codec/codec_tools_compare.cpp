// codec_tools_compare: the gain of each switchable .gvid tool of format 1.2, measured with P
// frames on one geometry video, and the peers with a GOP side by side:
//   - temporal-difference (TD) prediction on / off: BD-rate, lossless
//   - value-domain prediction (none / offset / weighted / affine): BD-rate against none, lossless
//   - near-lossless --max-error-mm: rate, PSNR and the max point error reached for each bound,
//     BD-rate against the QP curve, and each bound's rate next to the lossless rate
//   - per-plane QP offsets: BD-rate against none
//   - rate control: achieved bitrate and buffer fullness for several targets
//   - threads: encode wall time and bytes identical to one thread
//   - peers through libavcodec: FFV1 16-bit lossless, x264 10-bit and x265 12-bit 4:4:4 with the
//     given GOP (I every --gop frames, one B frame between P frames) at --peer-preset
// Usage: codec_tools_compare [--ict DIR | --gv DIR [--no-texture]] [--size N] [--frames N] [--gop
// N] [--bframes N]
//                            [--no-peers] [--peer-preset P] [--rate-only] [--subpel-only]
//                            [--bits-only] [--motion-only] [--bframes-only] [--transform-only]
//                            [--refs-only [--refs-preset fast|slow]] [--cross-plane-only]
//                            [--ctx-only]
//                            [--partitions-only [--partitions-preset fast|slow]]
//                            [--rdoq-only [--rdoq-preset fast|slow]] [--write-streams DIR]
//                            [--deblock-only [--deblock-preset fast|slow] [--deblock-beta N]
//                             [--deblock-tc N]] [--intra-rdo-only]
//                            [--temporal-contexts-only [--temporal-contexts-preset fast|slow]]
//                            [--merge-only] [--td16-only] [--quadratic-intra-only]
//                            [--resolution-only]
//                            [--speed-only [--speed-preset fast|slow]]
//                            [--threads-only [--threads-preset fast|slow]]
//                            [--tune-variant "KEY=VALUE [KEY=VALUE...]"]... [--variants-preset P]
//                            [--qps Q1,Q2,...]
// (--rate-only: the rate-control and threads tables only; --subpel-only: the motion precision
// rows and x265; --bits-only: where the bits go at QP -6, 0, 6, 12; --motion-only: the format
// 1.4 tools and x265, or with --no-peers the x265 points logged for the ICT face;
// --bframes-only: format 1.5, 0..3 B frames in both presets, B-frame QP offsets, lossless, and
// the BD-rates against 0 B frames and x265 (logged points with --no-peers); --refs-only: format
// 1.6, --refs 1, 2, 3, 5 in both presets (or the one of --refs-preset), lossless, and the
// BD-rates against --refs 1 and x265; --transform-only: format 1.6, --max-transform 4, 8, 16 in
// both presets, with P and B frames and intra only; --cross-plane-only: format 1.6 cross-plane
// residual prediction off / on (the other options at their defaults) in both presets, intra
// only, lossless and near-lossless, the BD-rates against off and x265, and how often each scale
// is coded; --ctx-only: format 1.7 cross-plane contexts off / on, the other options at their
// defaults, in both presets and lossless, the BD-rates against off and x265, and the bits per
// syntax group at QP 6 and 12 off and on; --partitions-only: format 1.7 inter partitions off /
// on in both presets, lossless, the BD-rates against off and x265, and the share of each
// partition type; --rdoq-only: rate-distortion optimised quantization off / on in both presets
// (or the one of --rdoq-preset), the BD-rates against off and x265, and the encode speed;
// --deblock-only: the format 1.8 deblocking filter off / on likewise, with the strength of
// --deblock-beta (quarter quantizer steps) and --deblock-tc (sixteenths; defaults: the
// encoder's); --intra-rdo-only: the fast preset's RDO in I frames off / on (the slow preset
// ignores the option); --temporal-contexts-only: format 1.9 temporal contexts off / on in both
// presets (or the one of --temporal-contexts-preset); --merge-only: format 1.11 merge off / on in
// both presets;
// --td16-only: format 1.12 TD16 off / on in both presets, and lossless (fast) off / on;
// --resolution-only: format 1.14 half resolution, --resolution full / auto in both presets;
// --quadratic-intra-only: format 1.13 quadratic intra off / on in both presets, and lossless
// (fast) off / on;
// --speed-only: the slow preset's speed decisions (encoder only) off, one at a time and
// together: encode frames per CPU second over all frames of each curve and the BD-rate against
// the decisions off; --threads-only: wall-clock encode rates with one and two threads (frame-level
// threads), three alternating rounds per preset and QP (default -10, 0, 12), bytes identical;
// --tune-variant (repeatable): the defaults and each variant (encoder tune keys, encoder_tune.hpp,
// space-separated in one argument), each as one curve: encode frames per CPU second over all frames
// of the curve and the BD-rate against the defaults, in both presets (or the one of
// --variants-preset);
// --no-texture: a --gv folder's X, Y, Z only;
// --write-streams DIR: also write every stream
// of ours to DIR/NNN_PRESET_qpQ.gvid, NNN in run order, e.g. for codec_decoder_benchmark;
// --qps: the QPs of our curves instead of the report's own, e.g. -18,...,24 for x265's whole
// range)
#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bd_rate.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/encoder_tune.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/half_resolution.hpp"
#include "gvkit/codec/surface_metrics.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "libav_peer.hpp"

namespace gvkit::bench {
namespace {
using namespace gvkit::codec;

double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}
double wall_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Material {
  std::vector<GeometryImage> frames;
  SequenceInfo info;
  double vertices = 0, peak = 0;
};

// --write-streams DIR: where run_ours writes each stream (empty: nowhere), and how many so far.
std::string g_stream_dir;
int g_streams_written = 0;

struct Run {
  RdPoint point;  // with the normal error (normal_db)
  SurfaceError surface;
  double max_mm = 0, encode_fps = 0, decode_fps = 0, kbps = 0;
  std::string bytes;
};

Run run_ours(const Material& m, const EncoderOptions& options,
             std::vector<FrameCodingStats>* stats = nullptr) {
  SequenceInfo info = m.info;
  info.bit_depth = options.bit_depth;
  Run run;
  double t0 = cpu_now();
  auto bytes = encode_gvid(m.frames, info, options, stats);
  if (!bytes.is_ok()) {
    std::fprintf(stderr, "encode failed: %s\n", bytes.status().message().c_str());
    std::exit(1);
  }
  run.encode_fps = m.frames.size() / (cpu_now() - t0);
  if (!g_stream_dir.empty()) {
    // --write-streams: every encoded stream, numbered in run order (for codec_decoder_benchmark).
    char name[64];
    std::snprintf(name, sizeof name, "/%03d_%s_qp%d.gvid", g_streams_written++,
                  preset_name(options.preset), options.qp);
    const std::string path = g_stream_dir + name;
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f || std::fwrite(bytes->data(), 1, bytes->size(), f) != bytes->size()) {
      std::fprintf(stderr, "cannot write %s\n", path.c_str());
      std::exit(1);
    }
    std::fclose(f);
  }
  auto reader = GvidReader::open_memory(*bytes, "tools").value();
  GeometryError total;
  int64_t bits = 0;
  double decode_seconds = 0;
  for (int64_t f = 0; f < reader->frame_count(); ++f) {
    t0 = cpu_now();
    GeometryImage decoded = reader->decode_frame(f).value();
    decode_seconds += cpu_now() - t0;
    accumulate(total, geometry_error(m.frames[f], decoded));
    accumulate(run.surface, surface_error(m.frames[f], decoded));
    bits += reader->frame_bits(f);
  }
  run.decode_fps = m.frames.size() / decode_seconds;
  run.max_mm = total.max_mm;
  run.point = {bits / m.vertices / m.frames.size(), total.psnr_db(m.peak),
               normal_quality_db(run.surface.normal_p95_deg())};
  run.kbps = bits / (m.frames.size() / m.info.fps) / 1000.0;
  run.bytes = std::move(bytes).value();
  return run;
}

void print_row(const std::string& name, const std::string& setting, const Run& r) {
  std::printf("| %s | %s | %.4f | %.2f | %.4f | %.2f | %.3f | %.1f | %.1f |\n", name.c_str(),
              setting.c_str(), r.point.rate, r.point.psnr_db, r.max_mm, r.surface.normal_p95_deg(),
              r.surface.hausdorff_mm, r.encode_fps, r.decode_fps);
  std::fflush(stdout);
}

void print_header() {
  std::printf(
      "\n| configuration | setting | bits/vertex/frame | PSNR (dB) | max error (mm) | normal error "
      "p95 (deg) | Hausdorff (mm) | encode fps (CPU) | decode fps (CPU) "
      "|\n|---|---|---|---|---|---|---|---|---|\n");
}

// A BD-rate row: over PSNR, and over the normal error (bd_rate.hpp) where both curves have it.
void print_bd(const std::string& what, const std::vector<RdPoint>& anchor,
              const std::vector<RdPoint>& test) {
  const auto cell = [](std::optional<double> bd) {
    char text[32] = "no overlap";
    if (bd) std::snprintf(text, sizeof text, "%+.2f %%", *bd);
    return std::string(text);
  };
  const bool normals = std::all_of(anchor.begin(), anchor.end(),
                                   [](const RdPoint& p) { return std::isfinite(p.normal_db); }) &&
                       std::all_of(test.begin(), test.end(),
                                   [](const RdPoint& p) { return std::isfinite(p.normal_db); });
  std::printf("| %s | %s | %s |\n", what.c_str(), cell(bd_rate_percent(anchor, test)).c_str(),
              normals ? cell(bd_rate_normal_percent(anchor, test)).c_str() : "-");
}

// `base` at each QP, a row per point; mean_encode_fps (optional): the mean of the rows' encode
// frames per CPU second.
std::vector<RdPoint> qp_curve(const Material& m, const EncoderOptions& base,
                              const std::string& name, const std::vector<int>& qps,
                              double* mean_encode_fps = nullptr) {
  std::vector<RdPoint> points;
  double fps = 0;
  for (int qp : qps) {
    EncoderOptions o = base;
    o.qp = qp;
    const Run r = run_ours(m, o);
    print_row(name, "qp " + std::to_string(qp), r);
    points.push_back(r.point);
    fps += r.encode_fps;
  }
  if (mean_encode_fps) *mean_encode_fps = qps.empty() ? 0.0 : fps / static_cast<double>(qps.size());
  return points;
}

// Motion vector precision (format 1.3): whole, half and quarter samples, everything else as
// `base`; RD curves, lossless rates and BD-rates against whole samples.
std::vector<std::vector<RdPoint>> report_subpel(const Material& m, const EncoderOptions& base,
                                                const std::vector<int>& qps) {
  print_header();
  std::vector<std::vector<RdPoint>> curves;
  const int precisions[3] = {0, 2, 4};
  const char* names[3] = {"whole-sample motion (--subpel 0)", "half-sample motion (--subpel 2)",
                          "quarter-sample motion (--subpel 4)"};
  for (int i = 0; i < 3; ++i) {
    EncoderOptions o = base;
    o.subpel = precisions[i];
    curves.push_back(qp_curve(m, o, names[i], qps));
  }
  for (int i = 0; i < 3; ++i) {
    EncoderOptions o = base;
    o.subpel = precisions[i];
    o.lossless = true;
    print_row(std::string("lossless, ") + names[i], "-", run_ours(m, o));
  }
  std::printf(
      "\n| BD-rate (piecewise cubic, over the common quality range) | over PSNR | over normal "
      "error |\n|---|---|---|\n");
  print_bd("half-sample vs whole-sample motion", curves[0], curves[1]);
  print_bd("quarter-sample vs whole-sample motion", curves[0], curves[2]);
  return curves;
}

// Where the bits go (format 1.4 accounting): per frame type, plane and syntax element group, in
// bits/vertex/frame (averaged over all frames of the sequence, so the rows add up to the rate).
void report_bit_accounting(const Material& m, const EncoderOptions& base,
                           const std::vector<int>& qps) {
  std::printf("\n| QP | frame type | plane | bits/vertex/frame |");
  for (int g = 0; g < kSyntaxGroupCount; ++g) std::printf(" %s |", syntax_group_name(g));
  std::printf(" MBs intra / inter / TD / skip |\n|---|---|---|---|");
  for (int g = 0; g < kSyntaxGroupCount; ++g) std::printf("---|");
  std::printf("---|\n");
  for (int qp : qps) {
    EncoderOptions o = base;
    o.qp = qp;
    std::vector<FrameCodingStats> stats;
    const Run r = run_ours(m, o, &stats);
    const double per = 1.0 / (m.vertices * static_cast<double>(m.frames.size()));
    for (const int type : {0, 1, 2}) {
      PlaneCodingStats all;
      std::vector<PlaneCodingStats> planes(3);
      bool any = false;
      for (const auto& f : stats)
        if ((f.intra ? 0 : (f.bidirectional ? 2 : 1)) == type) {
          any = true;
          for (size_t p = 0; p < 3 && p < f.planes.size(); ++p) {
            planes[p] += f.planes[p];
            all += f.planes[p];
          }
        }
      if (!any) continue;
      for (int p = 0; p <= 3; ++p) {
        const PlaneCodingStats& s = p < 3 ? planes[p] : all;
        static const char* const kTypes[3] = {"I", "P", "B"};
        static const char* const kPlanes[4] = {"X", "Y", "Z", "all"};
        std::printf("| %d | %s | %s | %.4f |", qp, kTypes[type], kPlanes[p], s.total_bits() * per);
        for (int g = 0; g < kSyntaxGroupCount; ++g)
          std::printf(" %.4f (%.0f %%) |", s.bits[g] * per,
                      100.0 * s.bits[g] / std::max(1.0, s.total_bits()));
        std::printf(" %lld / %lld / %lld / %lld |\n", static_cast<long long>(s.intra_mbs),
                    static_cast<long long>(s.inter_mbs), static_cast<long long>(s.td_mbs),
                    static_cast<long long>(s.skip_mbs));
      }
    }
    std::printf("| %d | total (stream) | | %.4f | PSNR %.2f dB |\n", qp, r.point.rate,
                r.point.psnr_db);

    std::fflush(stdout);
  }
}

// x265 12-bit 4:4:4 (I30 IPBPB, ref 5, slower, tune psnr) on the ICT face, 320x320, 30 frames,
// QP 0, 4, ..., 24, without x265's SEI option banner (2,226 bytes in the first packet, which the
// points logged before 2026-12-02 included): the points logged in docs/benchmarks.md (section
// "x265's option banner"), for BD-rates against x265 without re-running it (--no-peers).
const std::vector<RdPoint> kLoggedX265Ict = {{0.0712, 68.07}, {0.0486, 66.62}, {0.0351, 64.41},
                                             {0.0259, 61.91}, {0.0192, 59.21}, {0.0144, 57.17},
                                             {0.0108, 54.32}};

// Format 1.5: 0..3 B frames between anchors in the fast and the slow preset, B-frame QP offsets
// (fast, one B frame) and lossless; BD-rates against 0 B frames (the 1.4 stream) of the same
// preset and against x265.
void report_bframes(const Material& m, const EncoderOptions& base, const std::vector<int>& qps,
                    const std::vector<RdPoint>& x265, const std::string& source) {
  print_header();
  std::vector<std::vector<RdPoint>> curves[2];
  const Preset presets[2] = {Preset::kFast, Preset::kSlow};
  for (int p = 0; p < 2; ++p)
    for (int b = 0; b <= 3; ++b) {
      EncoderOptions o = base;
      o.preset = presets[p];
      o.bframes = b;
      curves[p].push_back(qp_curve(m, o,
                                   std::string(preset_name(presets[p])) + ", --bframes " +
                                       std::to_string(b) +
                                       (b ? " --b-qp-offset " + std::to_string(o.b_qp_offset) : ""),
                                   qps));
    }
  // (preset, offset) pairs; the default offset (2) is in the curves above.
  const std::pair<Preset, int> offsets[5] = {{Preset::kFast, 0},
                                             {Preset::kFast, 4},
                                             {Preset::kFast, 6},
                                             {Preset::kSlow, 0},
                                             {Preset::kSlow, 4}};
  std::vector<std::vector<RdPoint>> offset_curves;
  const auto offset_name = [&](int i) {
    return std::string(preset_name(offsets[i].first)) + ", --bframes 1 --b-qp-offset " +
           std::to_string(offsets[i].second);
  };
  for (int i = 0; i < 5; ++i) {
    EncoderOptions o = base;
    o.preset = offsets[i].first;
    o.bframes = 1;
    o.b_qp_offset = offsets[i].second;
    offset_curves.push_back(qp_curve(m, o, offset_name(i), qps));
  }
  for (int b = 0; b <= 3; ++b) {
    EncoderOptions o = base;
    o.bframes = b;
    o.lossless = true;
    print_row("lossless, fast, --bframes " + std::to_string(b), "-", run_ours(m, o));
  }
  std::printf(
      "\n| BD-rate (piecewise cubic, over the common quality range) | over PSNR | over normal "
      "error |\n|---|---|---|\n");
  for (int p = 0; p < 2; ++p)
    for (int b = 1; b <= 3; ++b)
      print_bd(std::string(preset_name(presets[p])) + ", --bframes " + std::to_string(b) + " vs 0",
               curves[p][0], curves[p][b]);
  for (int i = 0; i < 5; ++i)
    print_bd(offset_name(i) + " vs 0 B frames", curves[offsets[i].first == Preset::kSlow][0],
             offset_curves[i]);
  for (int p = 0; p < 2; ++p)
    for (int b = 0; b <= 3; ++b)
      print_bd(std::string(preset_name(presets[p])) + ", --bframes " + std::to_string(b) +
                   " vs x265 12-bit (" + source + " points)",
               x265, curves[p][b]);
  for (int i = 0; i < 5; ++i)
    print_bd(offset_name(i) + " vs x265 (" + source + " points)", x265, offset_curves[i]);
}

// Format 1.6, larger transforms: --max-transform 4, 8 and 16 in both presets, with P and B
// frames and intra only; BD-rates against 4 (the stream without the tool) and against x265, and
// at QP 0 how many inter / I16x16 macroblocks took each size.
void report_transforms(const Material& m, const EncoderOptions& base, const std::vector<int>& qps,
                       const std::vector<RdPoint>& x265, const std::string& source) {
  print_header();
  const Preset presets[2] = {Preset::kFast, Preset::kSlow};
  const int sizes[3] = {4, 8, 16};
  std::vector<RdPoint> curves[2][2][3];  // [intra only][preset][size]
  const auto name = [&](int intra, int p, int s) {
    return std::string(intra ? "intra only, " : "") + preset_name(presets[p]) +
           ", --max-transform " + std::to_string(sizes[s]);
  };
  for (int intra = 0; intra < 2; ++intra)
    for (int p = 0; p < 2; ++p)
      for (int s = 0; s < 3; ++s) {
        EncoderOptions o = base;
        o.preset = presets[p];
        o.max_transform = sizes[s];
        o.intra_only = intra != 0;
        curves[intra][p][s] = qp_curve(m, o, name(intra, p, s), qps);
      }
  std::printf(
      "\n| BD-rate (piecewise cubic, over the common quality range) | over PSNR | over normal "
      "error |\n|---|---|---|\n");
  for (int intra = 0; intra < 2; ++intra)
    for (int p = 0; p < 2; ++p)
      for (int s = 1; s < 3; ++s)
        print_bd(name(intra, p, s) + " vs 4", curves[intra][p][0], curves[intra][p][s]);
  for (int p = 0; p < 2; ++p)
    for (int s = 0; s < 3; ++s)
      print_bd(name(0, p, s) + " vs x265 12-bit (" + source + " points)", x265, curves[0][p][s]);
  std::printf(
      "\n| QP 0 | bits/vertex/frame | 8x8 MBs | 16x16 MBs | intra + plain inter MBs | "
      "sig_map bits | levels bits |\n|---|---|---|---|---|---|---|\n");
  for (int p = 0; p < 2; ++p)
    for (int s = 0; s < 3; ++s) {
      EncoderOptions o = base;
      o.preset = presets[p];
      o.max_transform = sizes[s];
      o.qp = 0;
      std::vector<FrameCodingStats> stats;
      const Run r = run_ours(m, o, &stats);
      PlaneCodingStats total;
      for (const auto& f : stats)
        for (const auto& plane : f.planes) total += plane;
      std::printf("| %s | %.4f | %lld | %lld | %lld | %.0f | %.0f |\n", name(0, p, s).c_str(),
                  r.point.rate, static_cast<long long>(total.transform8_mbs),
                  static_cast<long long>(total.transform16_mbs),
                  static_cast<long long>(total.inter_mbs + total.intra_mbs),
                  total.bits[kSyntaxSigMap], total.bits[kSyntaxLevels]);
    }
}

// half: the peer codes the frames halved as our encoder halves them (downsample_plane) and its
// output is upsampled by the format 1.14 filter before it is measured.
std::optional<Run> run_peer_config(const Material& m, const PeerConfig& config, bool half = false);

// Cross-plane scales coded by the Y and Z planes of a run, per scale (kCrossScales order).
struct ScaleCounts {
  int64_t n[kCrossScaleCount] = {};
  void add(const std::vector<FrameCodingStats>& stats) {
    for (const auto& f : stats)
      for (size_t p = 1; p < 3 && p < f.planes.size(); ++p)
        for (int i = 0; i < kCrossScaleCount; ++i) n[i] += f.planes[p].cross_scale_mbs[i];
  }
  std::string str() const {
    int64_t total = 0;
    for (int64_t v : n) total += v;
    if (total == 0) return "none coded";
    char buf[64];
    std::snprintf(buf, sizeof buf,
                  "%lld MBs coded a scale, %.1f %% nonzero:", static_cast<long long>(total),
                  100.0 * (total - n[4]) / total);
    std::string out = buf;
    for (int i = 0; i < kCrossScaleCount; ++i) {
      if (i == 4) continue;
      std::snprintf(buf, sizeof buf, " %+d: %.1f %%", kCrossScales[i], 100.0 * n[i] / total);
      out += buf;
    }
    return out;
  }
};

// Format 1.7: cross-plane contexts off and on (the other options at their defaults), fast and
// slow preset and lossless; BD-rates on vs off and against x265, then where the bits go at QP 6
// and 12 off and on, in each preset.
void report_cross_plane_contexts(const Material& m, const EncoderOptions& base,
                                 const std::vector<int>& qps, const std::vector<RdPoint>& x265,
                                 const std::string& source) {
  print_header();
  const Preset presets[2] = {Preset::kFast, Preset::kSlow};
  std::vector<RdPoint> curves[2][2];  // [preset][on]
  for (int k = 0; k < 2; ++k)
    for (const bool on : {false, true}) {
      const std::string name = std::string(preset_name(presets[k])) +
                               (on ? ", --cross-plane-contexts" : ", cross-plane contexts off");
      for (int qp : qps) {
        EncoderOptions o = base;
        o.preset = presets[k];
        o.qp = qp;
        o.cross_plane_contexts = on;
        const Run r = run_ours(m, o);
        print_row(name, "qp " + std::to_string(qp), r);
        curves[k][on].push_back(r.point);
      }
    }
  for (const bool on : {false, true}) {
    EncoderOptions o = base;
    o.lossless = true;
    o.cross_plane_contexts = on;
    const Run r = run_ours(m, o);
    print_row(std::string("lossless, fast") +
                  (on ? ", --cross-plane-contexts" : ", cross-plane contexts off"),
              "-", r);
  }
  std::printf(
      "\n| BD-rate (piecewise cubic, over the common quality range) | over PSNR | over normal "
      "error |\n|---|---|---|\n");
  for (int k = 0; k < 2; ++k)
    print_bd(std::string(preset_name(presets[k])) + ": --cross-plane-contexts vs off", curves[k][0],
             curves[k][1]);
  for (int k = 0; k < 2; ++k)
    for (int on = 0; on < 2; ++on)
      print_bd(std::string(preset_name(presets[k])) + (on ? ", --cross-plane-contexts" : ", off") +
                   " vs x265 12-bit (" + source + " points)",
               x265, curves[k][on]);
  for (const Preset preset : presets)
    for (const bool on : {false, true}) {
      std::printf("\nBits per syntax group, %s preset, cross-plane contexts %s:\n",
                  preset_name(preset), on ? "on" : "off");
      EncoderOptions o = base;
      o.preset = preset;
      o.cross_plane_contexts = on;
      report_bit_accounting(m, o, {6, 12});
    }
}

// One switchable tool off and on (set(options, on)) in each preset: the QP curves, the BD-rates
// of on against off and of both against x265, and the mean encode speed. The rows are named
// "PRESET, ON_FLAG" and "PRESET, OFF_FLAG".
template <class Set>
void report_on_off(const Material& m, const EncoderOptions& base, const std::vector<int>& qps,
                   const std::vector<RdPoint>& x265, const std::string& source,
                   const std::vector<Preset>& presets, const std::string& on_flag,
                   const std::string& off_flag, const Set& set) {
  print_header();
  std::vector<std::array<std::vector<RdPoint>, 2>> curves(presets.size());  // [preset][on]
  std::vector<std::array<double, 2>> fps(presets.size(), {0.0, 0.0});       // mean encode fps
  for (size_t k = 0; k < presets.size(); ++k)
    for (const bool on : {false, true}) {
      EncoderOptions o = base;
      o.preset = presets[k];
      set(o, on);
      curves[k][on] =
          qp_curve(m, o, std::string(preset_name(presets[k])) + ", " + (on ? on_flag : off_flag),
                   qps, &fps[k][on]);
    }
  std::printf(
      "\n| BD-rate (piecewise cubic, over the common quality range) | over PSNR | over normal "
      "error |\n|---|---|---|\n");
  for (size_t k = 0; k < presets.size(); ++k)
    print_bd(std::string(preset_name(presets[k])) + ": " + on_flag + " vs " + off_flag,
             curves[k][0], curves[k][1]);
  for (size_t k = 0; k < presets.size(); ++k)
    for (int on = 0; on < 2; ++on)
      print_bd(std::string(preset_name(presets[k])) + ", " + (on ? on_flag : off_flag) +
                   " vs x265 12-bit (" + source + " points)",
               x265, curves[k][on]);
  for (size_t k = 0; k < presets.size(); ++k)
    std::printf("\n%s preset: mean encode fps (CPU) %.2f with %s, %.2f with %s (%.3fx)\n",
                preset_name(presets[k]), fps[k][0], off_flag.c_str(), fps[k][1], on_flag.c_str(),
                fps[k][1] / fps[k][0]);
}

// Encoder speed decisions (encoder only, the stream syntax unchanged): per preset, the curve
// with every decision off (the encoder before them), each decision alone and all of them
// together; mean encode frames per CPU second and the BD-rate against the decisions off.
struct SpeedVariant {
  std::string name;
  std::function<void(EncoderOptions&)> set;
};
void report_speed(const Material& m, const EncoderOptions& base, const std::vector<int>& qps,
                  const std::vector<Preset>& presets, const std::vector<SpeedVariant>& variants) {
  print_header();
  for (const Preset preset : presets) {
    std::vector<std::vector<RdPoint>> curves;
    std::vector<double> fps(variants.size(), 0.0);
    for (size_t v = 0; v < variants.size(); ++v) {
      EncoderOptions o = base;
      o.preset = preset;
      variants[v].set(o);
      std::vector<RdPoint> points;
      double seconds = 0;  // CPU seconds of every encode of the curve
      for (int qp : qps) {
        o.qp = qp;
        const Run r = run_ours(m, o);
        print_row(std::string(preset_name(preset)) + ", " + variants[v].name,
                  "qp " + std::to_string(qp), r);
        points.push_back(r.point);
        seconds += static_cast<double>(m.frames.size()) / r.encode_fps;
      }
      curves.push_back(points);
      fps[v] = static_cast<double>(m.frames.size() * qps.size()) / seconds;
    }
    std::printf(
        "\n| %s preset | encode fps (CPU, all frames of the curve) | speed | BD-rate "
        "|\n|---|---|---|---|\n",
        preset_name(preset));
    for (size_t v = 0; v < variants.size(); ++v) {
      const auto bd = bd_rate_percent(curves[0], curves[v]);
      std::printf("| %s | %.2f | %.2fx | %s |\n", variants[v].name.c_str(), fps[v], fps[v] / fps[0],
                  bd ? (std::to_string(*bd).substr(0, 6) + " %").c_str() : "no overlap");
    }
    std::fflush(stdout);
  }
}

// Format 1.6: cross-plane residual prediction off and on, fast and slow preset, intra only (both
// presets), lossless and near-lossless; BD-rates on vs off and against x265, and the scales.
void report_cross_plane(const Material& m, const EncoderOptions& base, const std::vector<int>& qps,
                        const std::vector<RdPoint>& x265, const std::string& source) {
  print_header();
  struct Config {
    std::string name;
    EncoderOptions o;
  };
  std::vector<Config> configs;
  for (const Preset preset : {Preset::kFast, Preset::kSlow})
    for (const bool intra : {false, true}) {
      EncoderOptions o = base;
      o.preset = preset;
      o.intra_only = intra;
      configs.push_back({std::string(preset_name(preset)) + (intra ? ", intra only" : ""), o});
    }
  std::vector<std::vector<RdPoint>> curves[2];
  std::vector<std::string> scale_lines;
  for (const Config& c : configs)
    for (const bool on : {false, true}) {
      const std::string name = c.name + (on ? ", --cross-plane" : ", cross-plane off");
      ScaleCounts counts;
      std::vector<RdPoint> points;
      for (int qp : qps) {
        EncoderOptions o = c.o;
        o.qp = qp;
        o.cross_plane = on;
        std::vector<FrameCodingStats> stats;
        const Run r = run_ours(m, o, &stats);
        print_row(name, "qp " + std::to_string(qp), r);
        points.push_back(r.point);
        counts.add(stats);
      }
      curves[on].push_back(points);
      if (on) scale_lines.push_back(c.name + ": " + counts.str());
    }
  for (const double max_error : {0.0, 0.05})
    for (const bool on : {false, true}) {
      EncoderOptions o = base;
      o.lossless = max_error == 0;
      o.max_error_mm = max_error;
      o.cross_plane = on;
      std::vector<FrameCodingStats> stats;
      const Run r = run_ours(m, o, &stats);
      print_row(std::string(max_error == 0 ? "lossless" : "near-lossless E = 0.05 mm") + ", fast" +
                    (on ? ", --cross-plane" : ", cross-plane off"),
                "-", r);
      if (on) {
        ScaleCounts counts;
        counts.add(stats);
        scale_lines.push_back(std::string(max_error == 0 ? "lossless" : "near-lossless") + ": " +
                              counts.str());
      }
    }
  std::printf(
      "\n| BD-rate (piecewise cubic, over the common quality range) | over PSNR | over normal "
      "error |\n|---|---|---|\n");
  for (size_t i = 0; i < configs.size(); ++i)
    print_bd(configs[i].name + ": --cross-plane vs off", curves[0][i], curves[1][i]);
  for (size_t i = 0; i < configs.size(); ++i)
    for (int on = 0; on < 2; ++on)
      print_bd(configs[i].name + (on ? ", --cross-plane" : ", off") + " vs x265 12-bit (" + source +
                   " points)",
               x265, curves[on][i]);
  std::printf("\nCross-plane scales of the Y and Z planes (all QPs of the curve):\n");
  for (const auto& line : scale_lines) std::printf("  %s\n", line.c_str());
}

// Format 1.7, inter partitions: off and on in the fast and slow presets (QP curves, the other
// options at their defaults), lossless in both presets; BD-rates on vs off and against x265, and
// the share of the plain inter macroblocks of the P planes per partition type.
void report_partitions(const Material& m, const EncoderOptions& base, const std::vector<int>& qps,
                       const std::vector<RdPoint>& x265, const std::string& source,
                       const std::vector<Preset>& presets) {
  print_header();
  const size_t n = presets.size();
  std::vector<RdPoint> curves[2][2];  // [preset][on]
  std::vector<std::string> share_lines;
  const auto share = [](const std::vector<FrameCodingStats>& stats) {
    int64_t n[4] = {};
    for (const auto& f : stats)
      for (const auto& plane : f.planes)
        for (int t = 0; t < 4; ++t) n[t] += plane.partition_mbs[t];
    const int64_t total = n[0] + n[1] + n[2] + n[3];
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "%lld plain inter MBs: 16x16 %.1f %%, 16x8 %.1f %%, 8x16 %.1f %%, 8x8 %.1f %%",
                  static_cast<long long>(total), 100.0 * n[0] / std::max<int64_t>(1, total),
                  100.0 * n[1] / std::max<int64_t>(1, total),
                  100.0 * n[2] / std::max<int64_t>(1, total),
                  100.0 * n[3] / std::max<int64_t>(1, total));
    return std::string(buf);
  };
  for (size_t p = 0; p < n; ++p)
    for (int on = 0; on < 2; ++on) {
      const std::string name =
          std::string(preset_name(presets[p])) + (on ? ", --partitions" : ", partitions off");
      std::vector<FrameCodingStats> all;
      for (int qp : qps) {
        EncoderOptions o = base;
        o.preset = presets[p];
        o.qp = qp;
        o.partitions = on != 0;
        std::vector<FrameCodingStats> stats;
        const Run r = run_ours(m, o, &stats);
        print_row(name, "qp " + std::to_string(qp), r);
        curves[p][on].push_back(r.point);
        if (on) share_lines.push_back(name + ", qp " + std::to_string(qp) + ": " + share(stats));
      }
    }
  for (size_t p = 0; p < n; ++p)
    for (int on = 0; on < 2; ++on) {
      EncoderOptions o = base;
      o.preset = presets[p];
      o.lossless = true;
      o.partitions = on != 0;
      std::vector<FrameCodingStats> stats;
      const Run r = run_ours(m, o, &stats);
      const std::string name = std::string("lossless, ") + preset_name(presets[p]) +
                               (on ? ", --partitions" : ", partitions off");
      print_row(name, "-", r);
      if (on) share_lines.push_back(name + ": " + share(stats));
    }
  std::printf(
      "\n| BD-rate (piecewise cubic, over the common quality range) | over PSNR | over normal "
      "error |\n|---|---|---|\n");
  for (size_t p = 0; p < n; ++p)
    print_bd(std::string(preset_name(presets[p])) + ": --partitions vs off", curves[p][0],
             curves[p][1]);
  for (size_t p = 0; p < n; ++p)
    for (int on = 0; on < 2; ++on)
      print_bd(std::string(preset_name(presets[p])) + (on ? ", --partitions" : ", off") +
                   " vs x265 12-bit (" + source + " points)",
               x265, curves[p][on]);
  std::printf("\nPartition types of the P planes' plain inter macroblocks:\n");
  for (const auto& line : share_lines) std::printf("  %s\n", line.c_str());
}

// Format 1.6, multiple reference frames: --refs 1, 2, 3, 5 in the given presets (QP curves),
// lossless (fast), and the BD-rates against --refs 1 and against x265.
void report_refs(const Material& m, const EncoderOptions& base, const std::vector<int>& qps,
                 const std::vector<RdPoint>& x265, const std::string& source,
                 const std::vector<Preset>& presets) {
  print_header();
  const int refs[4] = {1, 2, 3, 5};
  std::vector<std::vector<RdPoint>> curves[2];
  for (size_t p = 0; p < presets.size(); ++p)
    for (int r : refs) {
      EncoderOptions o = base;
      o.preset = presets[p];
      o.refs = r;
      curves[p].push_back(qp_curve(
          m, o, std::string(preset_name(presets[p])) + ", --refs " + std::to_string(r), qps));
    }
  for (int r : refs) {
    EncoderOptions o = base;
    o.lossless = true;
    o.refs = r;
    print_row("lossless, fast, --refs " + std::to_string(r), "-", run_ours(m, o));
  }
  std::printf(
      "\n| BD-rate (piecewise cubic, over the common quality range) | over PSNR | over normal "
      "error |\n|---|---|---|\n");
  for (size_t p = 0; p < presets.size(); ++p)
    for (int i = 1; i < 4; ++i)
      print_bd(std::string(preset_name(presets[p])) + ", --refs " + std::to_string(refs[i]) +
                   " vs --refs 1",
               curves[p][0], curves[p][i]);
  for (size_t p = 0; p < presets.size(); ++p)
    for (int i = 0; i < 4; ++i)
      print_bd(std::string(preset_name(presets[p])) + ", --refs " + std::to_string(refs[i]) +
                   " vs x265 12-bit (" + source + " points)",
               x265, curves[p][i]);
}

// x265 12-bit 4:4:4 with the GOP, one B frame and 5 references at --peer-preset, QP 0 .. 24.
std::vector<RdPoint> run_x265(const Material& m, int gop, const std::string& peer_preset,
                              bool half = false) {
  print_header();
  std::vector<RdPoint> points;
  PeerConfig x265{"libx265", "yuv444p12le", 12, {{"preset", peer_preset}, {"tune", "psnr"}}};
  x265.gop = gop;
  x265.bframes = 1;
  for (int qp : {0, 4, 8, 12, 16, 20, 24}) {
    PeerConfig c = x265;
    c.options.push_back({"x265-params", "log-level=error:keyint=" + std::to_string(gop) +
                                            ":bframes=1:ref=5:qp=" + std::to_string(qp)});
    auto r = run_peer_config(m, c, half);
    if (!r) break;
    print_row("x265 12-bit 4:4:4, I" + std::to_string(gop) + " IPBPB ref 5, " + peer_preset +
                  (half ? ", half resolution (1.14 filters)" : ""),
              "qp " + std::to_string(qp), *r);
    points.push_back(r->point);
  }
  return points;
}

// Format 1.4 tools: shared motion (syntax) and inter decimation (encoder only), each on and off
// against the 1.3 encoder configuration, then variants; returns the curves and (names) their
// labels: 0 1.3, 1 shared motion, 2 decimation (the 1.4 defaults), 3 both, 4 both + skip
// check, 5 both + P-frame QP offset 9, 6 both in the slow preset, 7 1.3 in the slow preset.
std::vector<std::vector<RdPoint>> report_motion_tools(const Material& m, const EncoderOptions& base,
                                                      const std::vector<int>& qps,
                                                      std::vector<std::string>* names) {
  print_header();
  std::vector<std::vector<RdPoint>> curves;
  const auto add = [&](const std::string& name, const EncoderOptions& o) {
    names->push_back(name);
    curves.push_back(qp_curve(m, o, name, qps));
  };
  const char* labels[4] = {"1.3 encoder (--no-decimation)", "--shared-motion --no-decimation",
                           "inter decimation (1.4 defaults)",
                           "--shared-motion with inter decimation"};
  for (int i = 0; i < 4; ++i) {
    EncoderOptions o = base;
    o.shared_motion = (i & 1) != 0;
    o.inter_decimation = (i & 2) != 0;
    add(labels[i], o);
  }
  for (int i : {0, 2, 3}) {
    EncoderOptions o = base;
    o.shared_motion = (i & 1) != 0;
    o.inter_decimation = (i & 2) != 0;
    o.lossless = true;
    print_row(std::string("lossless, ") + labels[i], "-", run_ours(m, o));
  }
  EncoderOptions o = base;
  o.shared_motion = true;
  o.skip_check = true;
  add("shared motion + decimation + --skip-check", o);
  o.skip_check = false;
  o.p_qp_offset = 9;
  add("shared motion + decimation + --p-qp-offset 9", o);
  o.p_qp_offset = base.p_qp_offset;
  o.preset = Preset::kSlow;
  add("shared motion + decimation, slow preset (RDO)", o);
  o.shared_motion = false;
  o.inter_decimation = false;
  add("1.3 encoder, slow preset (RDO)", o);
  std::printf(
      "\n| BD-rate (piecewise cubic, over the common quality range) | over PSNR | over normal "
      "error |\n|---|---|---|\n");
  print_bd("shared motion vs 1.3", curves[0], curves[1]);
  print_bd("inter decimation vs 1.3", curves[0], curves[2]);
  print_bd("shared motion + decimation vs 1.3", curves[0], curves[3]);
  print_bd("shared motion vs none, both with decimation", curves[2], curves[3]);
  print_bd("--skip-check vs shared motion + decimation", curves[3], curves[4]);
  print_bd("--p-qp-offset 9 vs 6, shared motion + decimation", curves[3], curves[5]);
  print_bd("shared motion + decimation vs 1.3 encoder, slow preset", curves[7], curves[6]);
  return curves;
}

std::optional<Run> run_peer_config(const Material& m, const PeerConfig& config, bool half) {
  SequenceInfo info = m.info;
  info.bit_depth = config.bit_depth;
  std::vector<std::vector<SamplePlane>> planes;
  for (const auto& f : m.frames) {
    planes.push_back(quantize_geometry(f, info));
    if (half)
      for (SamplePlane& p : planes.back())
        p = downsample_plane(p, info.width, info.height, info.bit_depth);
  }
  const int width = half ? half_size(info.width) : info.width;
  const int height = half ? half_size(info.height) : info.height;
  auto run = run_peer(planes, width, height, config);
  if (!run.is_ok()) {
    std::fprintf(stderr, "%s\n", run.status().message().c_str());
    return std::nullopt;
  }
  GeometryError total;
  Run r;
  int64_t bytes = 0;
  for (size_t f = 0; f < m.frames.size(); ++f) {
    if (half)
      for (SamplePlane& p : run->decoded[f])
        p = upsample_half_plane(p, info.width, info.height, info.bit_depth);
    const GeometryImage decoded = dequantize_geometry(run->decoded[f], info, f);
    accumulate(total, geometry_error(m.frames[f], decoded));
    accumulate(r.surface, surface_error(m.frames[f], decoded));
    bytes += run->frame_bytes[f];
  }
  r.encode_fps = m.frames.size() / run->encode_seconds;
  r.decode_fps = m.frames.size() / run->decode_seconds;
  r.max_mm = total.max_mm;
  r.point = {bytes * 8.0 / m.vertices / m.frames.size(), total.psnr_db(m.peak),
             normal_quality_db(r.surface.normal_p95_deg())};
  return r;
}

// Rate control (achieved rate, buffer) and threads (wall time, identical bytes).
void report_rate_and_threads(const Material& m, const EncoderOptions& base) {
  // Rate control: the constant-QP rates bracket the targets.
  std::printf(
      "\n| rate control target (kbit/s) | achieved (kbit/s) | PSNR (dB) | max buffer fullness "
      "(%% of 1 s buffer) |\n|---|---|---|---|\n");
  for (double target : {500.0, 1000.0, 2000.0, 4000.0}) {
    EncoderOptions o = base;
    o.bitrate_kbps = target;
    o.buffer_seconds = 1.0;
    RateController rate(o, m.info.fps);
    std::vector<SamplePlane> reference;
    int64_t bits = 0;
    GeometryError total;
    for (size_t i = 0; i < m.frames.size(); ++i) {
      auto e =
          encode_sequence_frame(m.frames[i], m.info, o, static_cast<uint32_t>(i), reference, &rate);
      reference = e->planes;
      bits += static_cast<int64_t>(e->packet.size()) * 8;
      accumulate(total, geometry_error(m.frames[i], e->reconstruction));
    }
    std::printf("| %.0f | %.1f | %.2f | %.1f |\n", target,
                bits / (m.frames.size() / m.info.fps) / 1000.0, total.psnr_db(m.peak),
                100.0 * rate.max_fullness_bits() / rate.buffer_bits());
    std::fflush(stdout);
  }

  // Threads: wall time, identical bytes.
  std::printf(
      "\n| threads | preset | encode fps (wall) | bytes identical to 1 thread "
      "|\n|---|---|---|---|\n");
  for (Preset preset : {Preset::kFast, Preset::kSlow}) {
    std::string one;
    for (int threads : {1, 2, 3}) {
      EncoderOptions o = base;
      o.preset = preset;
      o.qp = 0;
      o.threads = threads;
      const double t0 = wall_now();
      auto bytes = encode_gvid(m.frames, m.info, o).value();
      const double fps = m.frames.size() / (wall_now() - t0);
      if (threads == 1) one = bytes;
      std::printf("| %d | %s | %.1f | %s |\n", threads, preset_name(preset), fps,
                  bytes == one ? "yes" : "NO");
      std::fflush(stdout);
    }
  }
}

// Thread scaling (--threads-only): per preset and QP, the wall-clock encode rate with one and
// with two threads (frame-level threads: B frames beside the next anchor; planes in parallel),
// measured in `rounds` alternating rounds, and whether the bytes are the same.
void report_thread_scaling(const Material& m, const EncoderOptions& base,
                           const std::vector<int>& qps, const std::vector<Preset>& presets,
                           int rounds) {
  std::printf(
      "\n| preset | QP | 1 thread fps (wall, per round) | 2 threads fps (wall, per round) | "
      "speed-up (median rounds) | bytes identical |\n|---|---|---|---|---|---|\n");
  for (const Preset preset : presets)
    for (const int qp : qps) {
      std::vector<double> fps[2];
      bool same = true;
      for (int round = 0; round < rounds; ++round) {
        std::string one;
        for (const int threads : {1, 2}) {
          EncoderOptions o = base;
          o.preset = preset;
          o.qp = qp;
          o.threads = threads;
          const double t0 = wall_now();
          auto bytes = encode_gvid(m.frames, m.info, o).value();
          fps[threads - 1].push_back(static_cast<double>(m.frames.size()) / (wall_now() - t0));
          if (threads == 1)
            one = std::move(bytes);
          else
            same = same && bytes == one;
        }
      }
      const auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
      };
      const auto list = [](const std::vector<double>& v) {
        std::string text;
        for (double x : v) text += (text.empty() ? "" : " / ") + std::to_string(x).substr(0, 5);
        return text;
      };
      std::printf("| %s | %d | %s | %s | %.2fx | %s |\n", preset_name(preset), qp,
                  list(fps[0]).c_str(), list(fps[1]).c_str(), median(fps[1]) / median(fps[0]),
                  same ? "yes" : "NO");
      std::fflush(stdout);
    }
}

// P- and B-frame QP offsets with every other option at its default, in one preset, over QP
// -18 .. 24 (the x265 points reach down to 54 dB, below the lowest PSNR of QP 12): curves and
// BD-rates against the default offsets and against x265.
void report_qp_offsets(const Material& m, const EncoderOptions& base, const std::vector<int>& qps,
                       const std::vector<RdPoint>& x265, const std::string& source) {
  print_header();
  struct Setting {
    int p, b;
  };
  const EncoderOptions defaults;
  std::vector<Setting> settings = {{defaults.p_qp_offset, defaults.b_qp_offset}};
  for (int p : {2, 4, 6, 8, 10})
    if (p != defaults.p_qp_offset) settings.push_back({p, defaults.b_qp_offset});
  for (int b : {0, 4}) settings.push_back({defaults.p_qp_offset, b});
  const auto name = [&](const Setting& s) {
    return std::string(preset_name(base.preset)) + ", --p-qp-offset " + std::to_string(s.p) +
           " --b-qp-offset " + std::to_string(s.b);
  };
  std::vector<std::vector<RdPoint>> curves;
  for (const Setting& s : settings) {
    EncoderOptions o = base;
    o.p_qp_offset = s.p;
    o.b_qp_offset = s.b;
    curves.push_back(qp_curve(m, o, name(s), qps));
  }
  std::printf(
      "\n| BD-rate (piecewise cubic, common quality range) | over PSNR | over normal error "
      "|\n|---|---|---|\n");
  for (size_t i = 1; i < settings.size(); ++i)
    print_bd(name(settings[i]) + " vs the defaults", curves[0], curves[i]);
  for (size_t i = 0; i < settings.size(); ++i)
    print_bd(name(settings[i]) + " vs x265 12-bit (" + source + " points)", x265, curves[i]);
  // The same against x265 with only QP -18 .. 12 (the range of the other modes' tables).
  for (size_t i = 0; i < settings.size(); ++i) {
    std::vector<RdPoint> upto12;
    for (size_t k = 0; k < qps.size(); ++k)
      if (qps[k] <= 12) upto12.push_back(curves[i][k]);
    print_bd(name(settings[i]) + ", QP -18 .. 12 only, vs x265 12-bit (" + source + " points)",
             x265, upto12);
  }
}

}  // namespace
}  // namespace gvkit::bench

int main(int argc, char** argv) {
  using namespace gvkit;
  using namespace gvkit::bench;
  std::string ict = "../shared/data/ict-facekit", gv_dir, peer_preset = "medium";
  bool peers = true, rate_only = false, subpel_only = false, bits_only = false, motion_only = false,
       bframes_only = false, refs_only = false, transform_only = false, cross_plane_only = false,
       qp_offsets_only = false, ctx_only = false, partitions_only = false, rdoq_only = false,
       deblock_only = false, intra_rdo_only = false, temporal_only = false, merge_only = false,
       td16_only = false, quadratic_only = false, resolution_only = false, speed_only = false,
       threads_only = false, no_texture = false;
  std::vector<std::string> tune_variants;  // --tune-variant
  DeblockingParams deblock;                // --deblock-beta / --deblock-tc (format 1.8)
  std::vector<Preset> refs_presets = {Preset::kFast, Preset::kSlow};
  Preset mode_preset = Preset::kFast;
  int gop = 30, bframes = -1;
  std::vector<int> qp_list;  // --qps: the QPs of the reports (default: each report's own)
  testing::GeometryVideoOptions vo;
  vo.frames = 30;
  // A preset name into *out, or a message on stderr and false.
  const auto read_preset = [](const char* name, Preset* out) {
    auto preset = parse_preset(name);
    if (!preset.is_ok()) {
      std::fprintf(stderr, "%s\n", preset.status().message().c_str());
      return false;
    }
    *out = *preset;
    return true;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--ict" && i + 1 < argc)
      ict = argv[++i];
    else if (a == "--gv" && i + 1 < argc)
      gv_dir = argv[++i];
    else if (a == "--no-texture")
      no_texture = true;
    else if (a == "--size" && i + 1 < argc)
      vo.size = std::atoi(argv[++i]);
    else if (a == "--frames" && i + 1 < argc)
      vo.frames = std::atoi(argv[++i]);
    else if (a == "--gop" && i + 1 < argc)
      gop = std::atoi(argv[++i]);
    else if (a == "--rate-only")
      rate_only = true;
    else if (a == "--subpel-only")
      subpel_only = true;
    else if (a == "--deblock-only")
      deblock_only = true;
    else if (a == "--intra-rdo-only")
      intra_rdo_only = true;
    else if (a == "--temporal-contexts-only")
      temporal_only = true;
    else if (a == "--speed-only")
      speed_only = true;
    else if (a == "--threads-only")
      threads_only = true;
    else if (a == "--tune-variant" && i + 1 < argc)
      tune_variants.push_back(argv[++i]);
    else if (a == "--merge-only")
      merge_only = true;
    else if (a == "--td16-only")
      td16_only = true;
    else if (a == "--quadratic-intra-only")
      quadratic_only = true;
    else if (a == "--resolution-only")
      resolution_only = true;
    else if (a == "--deblock-beta" && i + 1 < argc)
      deblock.beta = std::atoi(argv[++i]);
    else if (a == "--deblock-tc" && i + 1 < argc)
      deblock.tc = std::atoi(argv[++i]);
    else if (a == "--write-streams" && i + 1 < argc)
      g_stream_dir = argv[++i];
    else if (a == "--bits-only")
      bits_only = true;
    else if (a == "--qps" && i + 1 < argc) {
      std::stringstream list(argv[++i]);
      for (std::string qp; std::getline(list, qp, ',');) qp_list.push_back(std::atoi(qp.c_str()));
    } else if (a == "--preset" && i + 1 < argc) {
      if (!read_preset(argv[++i], &mode_preset)) return 2;
    } else if (a == "--motion-only")
      motion_only = true;
    else if (a == "--qp-offsets-only")
      qp_offsets_only = true;
    else if (a == "--bframes-only")
      bframes_only = true;
    else if (a == "--cross-plane-only")
      cross_plane_only = true;
    else if (a == "--ctx-only")
      ctx_only = true;
    else if (a == "--partitions-only")
      partitions_only = true;
    else if (a == "--rdoq-only")
      rdoq_only = true;
    else if (a == "--transform-only")
      transform_only = true;
    else if (a == "--refs-only")
      refs_only = true;
    else if ((a == "--refs-preset" || a == "--partitions-preset" || a == "--rdoq-preset" ||
              a == "--deblock-preset" || a == "--temporal-contexts-preset" ||
              a == "--speed-preset" || a == "--threads-preset" || a == "--variants-preset") &&
             i + 1 < argc) {
      Preset preset;
      if (!read_preset(argv[++i], &preset)) return 2;
      refs_presets = {preset};
    } else if (a == "--bframes" && i + 1 < argc)
      bframes = std::atoi(argv[++i]);
    else if (a == "--no-peers")
      peers = false;
    else if (a == "--peer-preset" && i + 1 < argc)
      peer_preset = argv[++i];
    else {
      std::fprintf(
          stderr,
          "usage: codec_tools_compare [--ict DIR | --gv DIR] [--size N] [--frames N] "
          "[--gop N] [--bframes N] [--no-peers] [--peer-preset P] [--rate-only] [--subpel-only] "
          "[--bits-only | --qp-offsets-only] [--preset P] [--motion-only] [--bframes-only] "
          "[--transform-only] [--refs-only [--refs-preset P]] [--cross-plane-only] [--ctx-only] "
          "[--partitions-only [--partitions-preset P]] [--rdoq-only [--rdoq-preset P]] "
          "[--deblock-only [--deblock-preset P] [--deblock-beta N] [--deblock-tc N]] "
          "[--intra-rdo-only] [--temporal-contexts-only [--temporal-contexts-preset P]] "
          "[--merge-only] [--td16-only] "
          "[--quadratic-intra-only] [--resolution-only] "
          "[--speed-only [--speed-preset P]] [--threads-only [--threads-preset P]] "
          "[--tune-variant \"KEY=VALUE [KEY=VALUE...]\"]... [--variants-preset P] "
          "[--write-streams DIR] [--qps Q1,Q2,...]\n");
      return 2;
    }
  }
  Material m;
  if (!gv_dir.empty()) {
    auto files = list_frame_files(gv_dir, ".exr");
    if (!files.is_ok() || files->empty()) {
      std::fprintf(stderr, "%s: no frame_NNNNNN.exr files\n", gv_dir.c_str());
      return 1;
    }
    for (const auto& f : *files) {
      m.frames.push_back(read_geometry_image_exr(f.path).value());
      if (no_texture) m.frames.back().texture = cv::Mat();  // --no-texture: X, Y, Z only
    }
  } else {
    auto frames = testing::make_ict_face_video(ict, vo);
    if (!frames.is_ok()) {
      std::fprintf(stderr, "%s\n", frames.status().message().c_str());
      return 1;
    }
    m.frames = std::move(frames).value();
  }
  auto info = codec::make_sequence_info(m.frames, 16, vo.fps);
  if (!info.is_ok()) {
    std::fprintf(stderr, "%s\n", info.status().message().c_str());
    return 1;
  }
  m.info = *info;
  m.vertices = static_cast<double>(m.info.domain_pixels());
  m.peak = m.info.box_diagonal_mm();
  std::printf(
      "material: %s, %dx%d, %zu frames, %.0f domain pixels, diagonal %.1f mm, 16-bit step "
      "%.5f mm; gvid: I frame every %d, P (and B) frames between, fast preset\n",
      gv_dir.empty() ? "ICT face in its UV layout" : gv_dir.c_str(), m.info.width, m.info.height,
      m.frames.size(), m.vertices, m.peak, m.info.step_mm(), gop);

  EncoderOptions base;
  base.preset = Preset::kFast;
  base.intra_period = gop;
  // The B frames of every row but those of --bframes-only (default: the encoder's, -1).
  base.bframes = bframes;
  base.deblock = deblock;
  const std::vector<int> qps = qp_list.empty() ? std::vector<int>{-18, -12, -6, 0, 6, 12} : qp_list;

  if (rate_only) {
    report_rate_and_threads(m, base);
    return 0;
  }
  if (bits_only) {
    EncoderOptions bits = base;
    bits.preset = mode_preset;
    report_bit_accounting(m, bits, qp_list.empty() ? std::vector<int>{-6, 0, 6, 12} : qp_list);
    return 0;
  }
  if (qp_offsets_only) {
    EncoderOptions o = base;
    o.preset = mode_preset;
    const std::vector<RdPoint> x265 = peers ? run_x265(m, gop, peer_preset) : kLoggedX265Ict;
    report_qp_offsets(m, o,
                      qp_list.empty() ? std::vector<int>{-18, -12, -6, 0, 6, 12, 18, 24} : qp_list,
                      x265, peers ? "this run" : "logged");
    return 0;
  }
  if (bframes_only) {
    const std::vector<RdPoint> x265 = peers ? run_x265(m, gop, peer_preset) : kLoggedX265Ict;
    report_bframes(m, base, qps, x265, peers ? "this run" : "logged");
    return 0;
  }
  if (cross_plane_only) {
    const std::vector<RdPoint> x265 = peers ? run_x265(m, gop, peer_preset) : kLoggedX265Ict;
    report_cross_plane(m, base, qps, x265, peers ? "this run" : "logged");
    return 0;
  }
  if (ctx_only) {
    const std::vector<RdPoint> x265 = peers ? run_x265(m, gop, peer_preset) : kLoggedX265Ict;
    report_cross_plane_contexts(m, base, qps, x265, peers ? "this run" : "logged");
    return 0;
  }
  if (partitions_only) {
    const std::vector<RdPoint> x265 = peers ? run_x265(m, gop, peer_preset) : kLoggedX265Ict;
    report_partitions(m, base, qps, x265, peers ? "this run" : "logged", refs_presets);
    return 0;
  }
  // One switchable tool off and on, in the presets given (BD-rates against off and x265).
  const auto on_off = [&](const std::vector<Preset>& presets, const char* on_flag,
                          const char* off_flag, auto set) {
    const std::vector<RdPoint> x265 = peers ? run_x265(m, gop, peer_preset) : kLoggedX265Ict;
    report_on_off(m, base, qps, x265, peers ? "this run" : "logged", presets, on_flag, off_flag,
                  set);
    return 0;
  };
  if (threads_only) {
    report_thread_scaling(m, base, qp_list.empty() ? std::vector<int>{-10, 0, 12} : qp_list,
                          refs_presets, 3);
    return 0;
  }
  if (!tune_variants.empty()) {
    std::vector<SpeedVariant> variants = {{"defaults", [](EncoderOptions&) {}}};
    for (const std::string& v : tune_variants) {
      std::vector<std::string> settings;
      std::stringstream list(v);
      for (std::string kv; list >> kv;) {
        EncoderOptions probe;  // the key and value checked before any encode
        const Status status = apply_tune(kv, &probe);
        if (!status.is_ok()) {
          std::fprintf(stderr, "--tune-variant %s: %s\n", kv.c_str(), status.message().c_str());
          return 2;
        }
        settings.push_back(kv);
      }
      variants.push_back({v, [settings](EncoderOptions& o) {
                            for (const std::string& kv : settings) (void)apply_tune(kv, &o);
                          }});
    }
    report_speed(m, base, qps, refs_presets, variants);
    return 0;
  }
  if (speed_only) {
    // Each variant sets every decision.
    const auto set = [](EncoderOptions& o, int shortlist, bool early_exit) {
      o.rdo_shortlist = shortlist;
      o.transform_early_exit = early_exit;
    };
    const std::vector<SpeedVariant> variants = {
        {"decisions off", [&](EncoderOptions& o) { set(o, 0, false); }},
        {"rdo-shortlist=3", [&](EncoderOptions& o) { set(o, 3, false); }},
        {"rdo-shortlist=2", [&](EncoderOptions& o) { set(o, 2, false); }},
        {"transform-early-exit", [&](EncoderOptions& o) { set(o, 0, true); }},
        {"rdo-shortlist=3 transform-early-exit", [&](EncoderOptions& o) { set(o, 3, true); }},
    };
    report_speed(m, base, qps, refs_presets, variants);
    return 0;
  }
  if (rdoq_only)
    return on_off(refs_presets, "--rdoq", "--no-rdoq",
                  [](EncoderOptions& o, bool on) { o.rdoq = on; });
  if (deblock_only)
    return on_off(refs_presets, "--deblock", "--no-deblock",
                  [](EncoderOptions& o, bool on) { o.deblocking = on; });
  if (merge_only)
    return on_off(refs_presets, "--merge", "--no-merge",
                  [](EncoderOptions& o, bool on) { o.merge = on; });
  // One tool off and on as on_off does, then lossless (fast preset) off and on.
  const auto on_off_lossless = [&](const char* on_flag, const char* off_flag, auto set) {
    on_off(refs_presets, on_flag, off_flag, set);
    print_header();
    for (const bool on : {false, true}) {
      EncoderOptions o = base;
      o.lossless = true;
      set(o, on);
      print_row(std::string("lossless, fast, ") + (on ? on_flag : off_flag), "-", run_ours(m, o));
    }
    return 0;
  };
  if (resolution_only) {
    const std::vector<RdPoint> x265 = peers ? run_x265(m, gop, peer_preset) : kLoggedX265Ict;
    report_on_off(m, base, qps, x265, peers ? "this run" : "logged", refs_presets,
                  "--resolution auto", "--resolution full", [](EncoderOptions& o, bool on) {
                    o.resolution = on ? Resolution::kAuto : Resolution::kFull;
                  });
    if (!peers) return 0;
    // x265 given the same halved frames, its output upsampled by the same filter: how much of
    // the gain is the resolution alone.
    const std::vector<RdPoint> x265_half = run_x265(m, gop, peer_preset, true);
    std::printf(
        "\n| BD-rate (piecewise cubic, over the common quality range) | over PSNR | over normal "
        "error |\n|---|---|---|\n");
    print_bd("x265 at half resolution vs x265", x265, x265_half);
    for (const Preset preset : refs_presets) {
      EncoderOptions o = base;
      o.preset = preset;
      o.resolution = Resolution::kHalf;
      const std::vector<RdPoint> ours =
          qp_curve(m, o, std::string(preset_name(preset)) + ", --resolution half", qps);
      print_bd(std::string(preset_name(preset)) + ", --resolution half vs x265 at half resolution",
               x265_half, ours);
    }
    return 0;
  }
  if (quadratic_only)
    return on_off_lossless("--quadratic-intra", "--no-quadratic-intra",
                           [](EncoderOptions& o, bool on) { o.quadratic_intra = on; });
  if (td16_only)
    return on_off_lossless("--td16", "--no-td16", [](EncoderOptions& o, bool on) { o.td16 = on; });
  if (temporal_only)
    return on_off(refs_presets, "--temporal-contexts", "--no-temporal-contexts",
                  [](EncoderOptions& o, bool on) { o.temporal_contexts = on; });
  if (intra_rdo_only)  // the slow preset ignores the option
    return on_off({Preset::kFast}, "--intra-rdo", "--no-intra-rdo",
                  [](EncoderOptions& o, bool on) { o.intra_rdo = on; });
  if (refs_only) {
    const std::vector<RdPoint> x265 = peers ? run_x265(m, gop, peer_preset) : kLoggedX265Ict;
    report_refs(m, base, qps, x265, peers ? "this run" : "logged", refs_presets);
    return 0;
  }
  if (transform_only) {
    const std::vector<RdPoint> x265 = peers ? run_x265(m, gop, peer_preset) : kLoggedX265Ict;
    report_transforms(m, base, qps, x265, peers ? "this run" : "logged");
    return 0;
  }
  if (motion_only) {
    std::vector<std::string> names;
    const auto curves = report_motion_tools(m, base, qps, &names);
    std::vector<RdPoint> x265_points = kLoggedX265Ict;
    std::string source = "logged";
    if (peers) {
      x265_points = run_x265(m, gop, peer_preset);
      source = "this run";
    }
    std::printf(
        "\n| BD-rate vs x265 12-bit (%s points) | over PSNR | over normal error |\n|---|---|---|\n",
        source.c_str());
    for (size_t i = 0; i < curves.size(); ++i)
      print_bd(names[i] + " vs x265", x265_points, curves[i]);
    return 0;
  }
  if (subpel_only) {
    const auto curves = report_subpel(m, base, qps);
    if (!peers) return 0;
    const std::vector<RdPoint> x265_points = run_x265(m, gop, peer_preset);
    std::printf("\n| BD-rate (piecewise cubic) | over PSNR | over normal error |\n|---|---|---|\n");
    print_bd("gvid fast, whole-sample motion vs x265", x265_points, curves[0]);
    print_bd("gvid fast, half-sample motion vs x265", x265_points, curves[1]);
    print_bd("gvid fast, quarter-sample motion vs x265", x265_points, curves[2]);
    return 0;
  }
  // Value-domain prediction.
  print_header();
  std::vector<std::vector<RdPoint>> vp_curves;
  const ValuePrediction modes[4] = {ValuePrediction::kNone, ValuePrediction::kOffset,
                                    ValuePrediction::kWeighted, ValuePrediction::kAffine};
  for (ValuePrediction mode : modes) {
    EncoderOptions o = base;
    o.value_prediction = mode;
    vp_curves.push_back(
        qp_curve(m, o, std::string("value prediction ") + value_prediction_name(mode), qps));
  }
  std::vector<double> lossless_bpv;
  for (ValuePrediction mode : modes) {
    EncoderOptions o = base;
    o.lossless = true;
    o.value_prediction = mode;
    const Run r = run_ours(m, o);
    print_row(std::string("lossless, value prediction ") + value_prediction_name(mode), "-", r);
    lossless_bpv.push_back(r.point.rate);
  }

  // Temporal-difference prediction off (everything else as the "none" curve).
  EncoderOptions no_td = base;
  no_td.td_prediction = false;
  const std::vector<RdPoint> no_td_curve = qp_curve(m, no_td, "TD prediction off", qps);
  no_td.lossless = true;
  const Run no_td_lossless = run_ours(m, no_td);
  print_row("lossless, TD prediction off", "-", no_td_lossless);

  // P-frame QP offsets.
  std::vector<std::vector<RdPoint>> pqp_curves;
  const int kOffsets[4] = {0, 3, 9, 12};  // the default, 6, is the "none" curve above
  for (int off : kOffsets) {
    EncoderOptions o = base;
    o.p_qp_offset = off;
    pqp_curves.push_back(qp_curve(m, o, "P-frame QP offset +" + std::to_string(off), qps));
  }

  // Near-lossless bounds (with affine value prediction and without).
  std::vector<RdPoint> near_points;
  for (double e : {0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0}) {
    EncoderOptions o = base;
    o.max_error_mm = e;
    const Run r = run_ours(m, o);
    char setting[64];
    std::snprintf(setting, sizeof setting, "E = %.2f mm (%.1f %% of lossless)", e,
                  100.0 * r.point.rate / lossless_bpv[0]);
    print_row("max-error-mm", setting, r);
    if (r.max_mm > e) std::printf("BOUND VIOLATED: %.5f > %.5f mm\n", r.max_mm, e);
    near_points.push_back(r.point);
  }

  // Per-plane QP offsets.
  std::vector<std::vector<RdPoint>> plane_curves;
  const int offsets[2][3] = {{0, 0, 3}, {3, 3, 0}};
  for (const auto& off : offsets) {
    EncoderOptions o = base;
    for (int i = 0; i < 3; ++i) o.plane_qp_offset[i] = off[i];
    plane_curves.push_back(qp_curve(m, o,
                                    "plane QP offsets " + std::to_string(off[0]) + "/" +
                                        std::to_string(off[1]) + "/" + std::to_string(off[2]),
                                    qps));
  }

  std::printf(
      "\n| BD-rate (piecewise cubic, over the common quality range) | over PSNR | over normal "
      "error |\n|---|---|---|\n");
  for (int i = 1; i < 4; ++i)
    print_bd(std::string("value prediction ") + value_prediction_name(modes[i]) + " vs none",
             vp_curves[0], vp_curves[i]);
  print_bd("TD prediction on vs off", no_td_curve, vp_curves[0]);
  print_bd("P-frame QP offset +6 (default) vs 0", pqp_curves[0], vp_curves[0]);
  for (int i = 1; i < 4; ++i)
    print_bd("P-frame QP offset +" + std::to_string(kOffsets[i]) + " vs 0", pqp_curves[0],
             pqp_curves[i]);
  print_bd("max-error-mm (near-lossless) vs QP curve", vp_curves[0], near_points);
  print_bd("plane QP offsets 0/0/+3 vs none", vp_curves[0], plane_curves[0]);
  print_bd("plane QP offsets +3/+3/0 vs none", vp_curves[0], plane_curves[1]);

  report_subpel(m, base, qps);
  report_rate_and_threads(m, base);

  if (peers) {
    print_header();
    const std::string keyint = std::to_string(gop);
    const auto sweep = [&](const std::string& name, PeerConfig config, const std::string& key,
                           const std::string& params, const std::vector<int>& peer_qps) {
      std::vector<RdPoint> points;
      for (int qp : peer_qps) {
        PeerConfig c = config;
        c.options.push_back({key, params + ":qp=" + std::to_string(qp)});
        auto r = run_peer_config(m, c);
        if (!r) break;
        print_row(name, "qp " + std::to_string(qp), *r);
        points.push_back(r->point);
      }
      return points;
    };
    PeerConfig x265{"libx265", "yuv444p12le", 12, {{"preset", peer_preset}, {"tune", "psnr"}}};
    x265.gop = gop;
    x265.bframes = 1;
    const auto x265_points =
        sweep("x265 12-bit 4:4:4, I" + keyint + " IPBPB ref 5, " + peer_preset, x265, "x265-params",
              "log-level=error:keyint=" + keyint + ":bframes=1:ref=5", {0, 4, 8, 12, 16, 20, 24});
    PeerConfig x264{"libx264", "yuv444p10le", 10, {{"preset", peer_preset}, {"tune", "psnr"}}};
    x264.gop = gop;
    x264.bframes = 1;
    const auto x264_points =
        sweep("x264 10-bit 4:4:4, I" + keyint + " IPBPB ref 5, " + peer_preset, x264, "x264-params",
              "keyint=" + keyint + ":bframes=1:ref=5", {0, 8, 16, 24});
    PeerConfig ffv1{"ffv1", "gbrp16le", 16, {{"level", "3"}, {"context", "1"}}};
    if (auto r = run_peer_config(m, ffv1)) {
      print_row("FFV1 16-bit gbrp16le lossless (level 3, context 1)", "-", *r);
      std::printf(
          "\ngvid lossless vs FFV1: %.3fx (TD on, value prediction none), %.3fx (TD on, affine), "
          "%.3fx (TD off)\n",
          lossless_bpv[0] / r->point.rate, lossless_bpv[3] / r->point.rate,
          no_td_lossless.point.rate / r->point.rate);
    }
    std::printf("\n| BD-rate (piecewise cubic) | over PSNR | over normal error |\n|---|---|---|\n");
    print_bd("gvid fast (value prediction none) vs x265", x265_points, vp_curves[0]);
    print_bd("gvid fast (value prediction affine) vs x265", x265_points, vp_curves[3]);
    print_bd("gvid fast (value prediction none) vs x264", x264_points, vp_curves[0]);
  }
  return 0;
}
