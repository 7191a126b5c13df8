// codec_rd_compare: rate-distortion of the .gvid codec (geometry modes on and off) and of its
// peers (x265 12-bit, x264 10-bit, FFV1 16-bit lossless) through libavcodec, intra-only, and of
// Draco per frame (mesh and point cloud, 11..16-bit positions; bench/codec/draco_peer.hpp), on
// the same geometry video and with the same metrics (geometry PSNR over domain pixels, peak = the
// bounding-box diagonal; the normal error's 95th percentile, codec/surface_metrics.hpp; bits per
// vertex per frame). Prints markdown tables; BD-rates over PSNR and over the normal error.
//
// Usage: codec_rd_compare [--ict DIR | --analytic] [--size N] [--frames N] [--no-peers]
//                         [--no-slow] [--gop N] [--draco | --no-draco] [--draco-level N]
#include <time.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "bd_rate.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/surface_metrics.hpp"
#include "libav_peer.hpp"
#ifdef GVKIT_HAVE_DRACO
#include "draco_peer.hpp"
#endif

namespace gvkit::bench {
namespace {
using namespace gvkit::codec;
// CPU time of the whole process (all threads): the machine is shared, so wall time is noisy;
// CPU seconds are what "frames per second on one core" means.
struct Clock {
  using time_point = double;
  static double now() {
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
  }
};

struct Curve {
  std::string name;
  std::vector<RdPoint> points;
  std::vector<std::string> labels;
  double encode_fps = 0, decode_fps = 0;  // of the last point run
};

struct Material {
  std::vector<GeometryImage> frames;
  SequenceInfo info;
  double vertices = 0, peak = 0;
};

double seconds_since(Clock::time_point t) { return (Clock::now() - t); }

// The 95th-percentile normal error (degrees) of a point measured with its normal error.
double normal_p95(const RdPoint& p) { return std::pow(10.0, -p.normal_db / 20.0); }

// One encode + decode of our codec; returns (rate, psnr) and the speeds.
RdPoint run_ours(const Material& m, const EncoderOptions& options, double* enc_fps, double* dec_fps,
                 double* max_mm) {
  SequenceInfo info = m.info;
  info.bit_depth = options.bit_depth;
  auto t0 = Clock::now();
  auto bytes = encode_gvid(m.frames, info, options);
  if (!bytes.is_ok()) {
    std::fprintf(stderr, "encode failed: %s\n", bytes.status().message().c_str());
    std::exit(1);
  }
  *enc_fps = m.frames.size() / seconds_since(t0);
  auto reader = GvidReader::open_memory(*bytes, "rd").value();
  GeometryError total;
  SurfaceError surface;
  int64_t bits = 0;
  double decode_seconds = 0;
  for (int64_t f = 0; f < reader->frame_count(); ++f) {
    t0 = Clock::now();
    GeometryImage decoded = reader->decode_frame(f).value();
    decode_seconds += seconds_since(t0);
    accumulate(total, geometry_error(m.frames[f], decoded));
    accumulate(surface, surface_error(m.frames[f], decoded));
    bits += reader->frame_bits(f);
  }
  *dec_fps = m.frames.size() / decode_seconds;
  *max_mm = total.max_mm;
  return {bits / m.vertices / m.frames.size(), total.psnr_db(m.peak),
          normal_quality_db(surface.normal_p95_deg())};
}

// Peer run on planes quantized by rounding in the same box at the peer's bit depth.
std::optional<RdPoint> run_libav(const Material& m, const PeerConfig& config, double* enc_fps,
                                 double* dec_fps, double* max_mm) {
  SequenceInfo info = m.info;
  info.bit_depth = config.bit_depth;
  std::vector<std::vector<SamplePlane>> planes;
  for (const auto& f : m.frames) planes.push_back(quantize_geometry(f, info));
  auto run = run_peer(planes, info.width, info.height, config);
  if (!run.is_ok()) {
    std::fprintf(stderr, "%s\n", run.status().message().c_str());
    return std::nullopt;
  }
  GeometryError total;
  SurfaceError surface;
  int64_t bytes = 0;
  for (size_t f = 0; f < m.frames.size(); ++f) {
    const GeometryImage decoded = dequantize_geometry(run->decoded[f], info, f);
    accumulate(total, geometry_error(m.frames[f], decoded));
    accumulate(surface, surface_error(m.frames[f], decoded));
    bytes += run->frame_bytes[f];
  }
  *enc_fps = m.frames.size() / run->encode_seconds;
  *dec_fps = m.frames.size() / run->decode_seconds;
  *max_mm = total.max_mm;
  return RdPoint{bytes * 8.0 / m.vertices / m.frames.size(), total.psnr_db(m.peak),
                 normal_quality_db(surface.normal_p95_deg())};
}

#ifdef GVKIT_HAVE_DRACO
// Draco per frame on the original frames; prints one row per quantization and returns the curve.
Curve run_draco(const Material& m, DracoGeometry geometry, int level) {
  Curve c;
  c.name = std::string("Draco ") + draco_geometry_name(geometry) +
           (geometry == DracoGeometry::kMesh ? " (edgebreaker" : " (kd-tree") + ", level " +
           std::to_string(level) + ")";
  for (int bits = 11; bits <= 16; ++bits) {
    DracoOptions o;
    o.geometry = geometry;
    o.quantization_bits = bits;
    o.compression_level = level;
    GeometryError total;
    SurfaceError surface;
    int64_t bytes = 0, lost = 0;
    double enc = 0, dec = 0;
    for (const GeometryImage& f : m.frames) {
      auto r = draco_round_trip(f, m.info, o);
      if (!r.is_ok()) {
        std::fprintf(stderr, "%s\n", r.status().message().c_str());
        std::exit(1);
      }
      accumulate(total, geometry_error(f, r->decoded));
      accumulate(surface, surface_error(f, r->decoded));
      bytes += r->bytes;
      enc += r->encode_seconds;
      dec += r->decode_seconds;
      lost += std::max<int64_t>(0, r->input_points - r->decoded_points);
    }
    const double n = static_cast<double>(m.frames.size());
    c.points.push_back({bytes * 8.0 / m.vertices / n, total.psnr_db(m.peak),
                        normal_quality_db(surface.normal_p95_deg())});
    c.labels.push_back(std::to_string(bits) + " bits");
    std::printf("| %s | %d bits | %.4f | %.2f | %.4f | %.4f | %.2f | %.1f | %.1f | %lld |\n",
                c.name.c_str(), bits, c.points.back().rate, c.points.back().psnr_db, total.rms_mm,
                total.max_mm, surface.normal_p95_deg(), n / enc, n / dec,
                static_cast<long long>(lost));
    std::fflush(stdout);
  }
  return c;
}
#endif

// A BD-rate row over PSNR and over the normal error.
void print_bd(const char* what, const Curve& anchor, const Curve& test) {
  const auto cell = [](std::optional<double> bd) {
    char text[32] = "no overlap";
    if (bd) std::snprintf(text, sizeof text, "%+.2f %%", *bd);
    return std::string(text);
  };
  std::printf("| %s | %s | %s |\n", what, cell(bd_rate_percent(anchor.points, test.points)).c_str(),
              cell(bd_rate_normal_percent(anchor.points, test.points)).c_str());
}

}  // namespace
}  // namespace gvkit::bench

int main(int argc, char** argv) {
  using namespace gvkit;
  using namespace gvkit::bench;
  std::string ict = "../shared/data/ict-facekit";
  bool analytic = false, peers = true, slow = true;
#ifdef GVKIT_HAVE_DRACO
  bool draco = true;
#else
  bool draco = false;
#endif
  int draco_level = 7;
  int gop = 1;  // our intra period: 1 = intra only (the peers are always intra only)
  testing::GeometryVideoOptions vo;
  vo.frames = 10;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--ict" && i + 1 < argc)
      ict = argv[++i];
    else if (a == "--analytic")
      analytic = true;
    else if (a == "--size" && i + 1 < argc)
      vo.size = std::atoi(argv[++i]);
    else if (a == "--frames" && i + 1 < argc)
      vo.frames = std::atoi(argv[++i]);
    else if (a == "--no-peers")
      peers = false;
    else if (a == "--no-slow")
      slow = false;
    else if (a == "--gop" && i + 1 < argc)
      gop = std::atoi(argv[++i]);
    else if (a == "--draco")
      draco = true;
    else if (a == "--no-draco")
      draco = false;
    else if (a == "--draco-level" && i + 1 < argc)
      draco_level = std::atoi(argv[++i]);
    else {
      std::fprintf(stderr,
                   "usage: codec_rd_compare [--ict DIR | --analytic] [--size N] "
                   "[--frames N] [--no-peers] [--no-slow] [--gop N] [--draco | --no-draco] "
                   "[--draco-level N]\n");
      return 2;
    }
  }
#ifndef GVKIT_HAVE_DRACO
  if (draco) {
    std::fprintf(stderr, "codec_rd_compare: built without Draco (libdraco-dev)\n");
    return 2;
  }
#endif
  Material m;
  if (analytic) {
    m.frames = testing::make_analytic_video(vo);
  } else {
    auto frames = testing::make_ict_face_video(ict, vo);
    if (!frames.is_ok()) {
      std::fprintf(stderr, "%s\n", frames.status().message().c_str());
      return 1;
    }
    m.frames = std::move(frames).value();
  }
  std::printf("gvid structure: %s\n",
              gop <= 1
                  ? "intra only"
                  : ("I frame every " + std::to_string(gop) + " frames, P frames between").c_str());
  m.info = codec::make_sequence_info(m.frames, 16, vo.fps).value();
  m.vertices = static_cast<double>(m.info.domain_pixels());
  m.peak = m.info.box_diagonal_mm();
  std::printf(
      "material: %s, %dx%d, %zu frames, %.0f domain pixels, diagonal %.1f mm, "
      "16-bit step %.5f mm\n",
      analytic ? "analytic surface" : "ICT face in its UV layout", m.info.width, m.info.height,
      m.frames.size(), m.vertices, m.peak, m.info.step_mm());

  const std::vector<int> our_qps = {-24, -18, -12, -6, 0, 6, 12};
  std::vector<Curve> ours;
  std::vector<std::pair<bool, codec::Preset>> configs = {{true, codec::Preset::kFast},
                                                         {false, codec::Preset::kFast}};
  if (slow) {
    configs.push_back({true, codec::Preset::kSlow});
    configs.push_back({false, codec::Preset::kSlow});
  }
  std::printf(
      "\n| configuration | QP | bits/vertex/frame | PSNR (dB) | max error (mm) | normal error p95 "
      "(deg) | encode fps | decode fps |\n|---|---|---|---|---|---|---|---|\n");
  for (const auto& [gv, preset] : configs) {
    Curve c;
    c.name = std::string("gvid ") + codec::preset_name(preset) +
             (gv ? ", geometry modes on" : ", geometry modes off");
    for (int qp : our_qps) {
      codec::EncoderOptions o;
      o.qp = qp;
      o.intra_period = gop;
      o.intra_only = gop <= 1;
      o.geometry_modes = gv;
      o.preset = preset;
      double ef, df, mx;
      c.points.push_back(run_ours(m, o, &ef, &df, &mx));
      c.labels.push_back("qp " + std::to_string(qp));
      std::printf("| %s | %d | %.4f | %.2f | %.3f | %.2f | %.1f | %.1f |\n", c.name.c_str(), qp,
                  c.points.back().rate, c.points.back().psnr_db, mx, normal_p95(c.points.back()),
                  ef, df);
      std::fflush(stdout);
    }
    ours.push_back(c);
  }
  std::vector<RdPoint> lossless_points;
  for (const auto& [gv, preset] : configs) {
    codec::EncoderOptions o;
    o.lossless = true;
    o.intra_period = gop;
    o.intra_only = gop <= 1;
    o.geometry_modes = gv;
    o.preset = preset;
    double ef, df, mx;
    const RdPoint p = run_ours(m, o, &ef, &df, &mx);
    lossless_points.push_back(p);
    std::printf("| gvid lossless %s, gv %s | - | %.4f | %.2f | %.4f | %.2f | %.1f | %.1f |\n",
                codec::preset_name(preset), gv ? "on" : "off", p.rate, p.psnr_db, mx, normal_p95(p),
                ef, df);
  }
  std::vector<Curve> peer_curves;
  if (peers) {
    struct PeerSweep {
      std::string name;
      PeerConfig config;
      std::string params_key;
      std::vector<int> qps;
    };
    std::vector<PeerSweep> sweeps = {
        {"x265 12-bit 4:4:4 intra (medium, tune psnr)",
         {"libx265", "yuv444p12le", 12, {{"preset", "medium"}, {"tune", "psnr"}}},
         "x265-params",
         {0, 4, 8, 12, 16, 20, 24, 28}},
        {"x264 10-bit 4:4:4 intra (medium, tune psnr)",
         {"libx264", "yuv444p10le", 10, {{"preset", "medium"}, {"tune", "psnr"}}},
         "x264-params",
         {0, 4, 8, 12, 16, 20, 24, 28}}};
    for (const PeerSweep& s : sweeps) {
      Curve c;
      c.name = s.name;
      for (int qp : s.qps) {
        PeerConfig config = s.config;
        config.options.push_back(
            {s.params_key,
             (s.params_key == "x265-params" ? "log-level=error:keyint=1:qp=" : "keyint=1:qp=") +
                 std::to_string(qp)});
        double ef, df, mx;
        auto p = run_libav(m, config, &ef, &df, &mx);
        if (!p) break;
        c.points.push_back(*p);
        c.labels.push_back("qp " + std::to_string(qp));
        std::printf("| %s | %d | %.4f | %.2f | %.3f | %.2f | %.1f | %.1f |\n", c.name.c_str(), qp,
                    p->rate, p->psnr_db, mx, normal_p95(*p), ef, df);
        std::fflush(stdout);
      }
      peer_curves.push_back(c);
    }
    struct Lossless {
      std::string name;
      PeerConfig config;
    };
    const std::vector<Lossless> lossless = {
        {"FFV1 16-bit gbrp16le lossless (level 3, context 1)",
         {"ffv1", "gbrp16le", 16, {{"level", "3"}, {"context", "1"}}}},
        {"x265 12-bit 4:4:4 lossless",
         {"libx265", "yuv444p12le", 12, {{"x265-params", "log-level=error:keyint=1:lossless=1"}}}}};
    for (const Lossless& l : lossless) {
      double ef, df, mx;
      auto p = run_libav(m, l.config, &ef, &df, &mx);
      if (p)
        std::printf("| %s | - | %.4f | %.2f | %.4f | %.2f | %.1f | %.1f |\n", l.name.c_str(),
                    p->rate, p->psnr_db, mx, normal_p95(*p), ef, df);
    }
  }
  std::vector<Curve> draco_curves;
  Curve fine;  // our best configuration at high rates, where Draco's curves lie
#ifdef GVKIT_HAVE_DRACO
  if (draco) {
    std::printf(
        "\n| Draco per frame | quantization | bits/vertex/frame | PSNR (dB) | RMS (mm) | max error "
        "(mm) | normal error p95 (deg) | encode fps | decode fps | points lost "
        "|\n|---|---|---|---|---|---|---|---|---|---|\n");
    for (const DracoGeometry g : {DracoGeometry::kMesh, DracoGeometry::kPointCloud})
      draco_curves.push_back(run_draco(m, g, draco_level));
    const auto& [gv, preset] = slow ? configs[2] : configs[0];
    fine.name = std::string("gvid ") + codec::preset_name(preset) + ", geometry modes on";
    std::printf(
        "\n| %s, high rates | QP | bits/vertex/frame | PSNR (dB) | max error (mm) | normal error "
        "p95 (deg) | encode fps | decode fps |\n|---|---|---|---|---|---|---|---|\n",
        fine.name.c_str());
    for (int qp : {-48, -42, -36, -30, -24, -18, -12}) {
      codec::EncoderOptions o;
      o.qp = qp;
      o.intra_period = gop;
      o.intra_only = gop <= 1;
      o.geometry_modes = gv;
      o.preset = preset;
      double ef, df, mx;
      fine.points.push_back(run_ours(m, o, &ef, &df, &mx));
      std::printf("| %s | %d | %.4f | %.2f | %.4f | %.2f | %.1f | %.1f |\n", fine.name.c_str(), qp,
                  fine.points.back().rate, fine.points.back().psnr_db, mx,
                  normal_p95(fine.points.back()), ef, df);
      std::fflush(stdout);
    }
    const RdPoint& ours_lossless = lossless_points[slow ? 2 : 0];
    const RdPoint& draco16 = draco_curves[0].points.back();
    std::printf(
        "\ngvid lossless (%s) %.4f bits/vertex/frame vs Draco mesh 16-bit %.4f: %.3fx (goal: "
        "below Draco at 16 bits: %s)\n",
        fine.name.c_str(), ours_lossless.rate, draco16.rate, ours_lossless.rate / draco16.rate,
        ours_lossless.rate < draco16.rate ? "met" : "not met");
  }
#endif
  std::printf("\n| BD-rate (piecewise cubic) | over PSNR | over normal error |\n|---|---|---|\n");
  print_bd("geometry modes on vs off, fast preset", ours[1], ours[0]);
  if (slow) print_bd("geometry modes on vs off, slow preset (RDO)", ours[3], ours[2]);
  const Curve& best = slow ? ours[2] : ours[0];
  for (const Curve& p : peer_curves) print_bd(("gvid vs " + p.name).c_str(), p, best);
  for (const Curve& d : draco_curves) {
    print_bd(("gvid vs " + d.name).c_str(), d, best);
    print_bd(("gvid high rates (QP -48..-12) vs " + d.name).c_str(), d, fine);
  }
  return 0;
}
