// codec_rd_compare: rate-distortion of the .gvid codec (geometry modes on and off) and of its
// peers (x265 12-bit, x264 10-bit, FFV1 16-bit lossless) through libavcodec, intra-only, on the
// same geometry video and with the same metric (geometry PSNR over domain pixels, peak = the
// bounding-box diagonal; bits per vertex per frame). Prints markdown tables.
//
// Usage: codec_rd_compare [--ict DIR | --analytic] [--size N] [--frames N] [--no-peers]
//                         [--no-slow] [--gop N]
#include <time.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "bd_rate.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "libav_peer.hpp"

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
  int64_t bits = 0;
  double decode_seconds = 0;
  for (int64_t f = 0; f < reader->frame_count(); ++f) {
    t0 = Clock::now();
    GeometryImage decoded = reader->decode_frame(f).value();
    decode_seconds += seconds_since(t0);
    accumulate(total, geometry_error(m.frames[f], decoded));
    bits += reader->frame_bits(f);
  }
  *dec_fps = m.frames.size() / decode_seconds;
  *max_mm = total.max_mm;
  return {bits / m.vertices / m.frames.size(), total.psnr_db(m.peak)};
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
  int64_t bytes = 0;
  for (size_t f = 0; f < m.frames.size(); ++f) {
    accumulate(total, geometry_error(m.frames[f], dequantize_geometry(run->decoded[f], info, f)));
    bytes += run->frame_bytes[f];
  }
  *enc_fps = m.frames.size() / run->encode_seconds;
  *dec_fps = m.frames.size() / run->decode_seconds;
  *max_mm = total.max_mm;
  return RdPoint{bytes * 8.0 / m.vertices / m.frames.size(), total.psnr_db(m.peak)};
}

void print_bd(const char* what, const Curve& anchor, const Curve& test) {
  const auto bd = bd_rate_percent(anchor.points, test.points);
  if (bd)
    std::printf("| %s | %+.2f %% |\n", what, *bd);
  else
    std::printf("| %s | no overlap |\n", what);
}

}  // namespace
}  // namespace gvkit::bench

int main(int argc, char** argv) {
  using namespace gvkit;
  using namespace gvkit::bench;
  std::string ict = "../shared/data/ict-facekit";
  bool analytic = false, peers = true, slow = true;
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
    else {
      std::fprintf(stderr,
                   "usage: codec_rd_compare [--ict DIR | --analytic] [--size N] "
                   "[--frames N] [--no-peers] [--no-slow] [--gop N]\n");
      return 2;
    }
  }
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
      "\n| configuration | QP | bits/vertex/frame | PSNR (dB) | max error (mm) | encode "
      "fps | decode fps |\n|---|---|---|---|---|---|---|\n");
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
      std::printf("| %s | %d | %.4f | %.2f | %.3f | %.1f | %.1f |\n", c.name.c_str(), qp,
                  c.points.back().rate, c.points.back().psnr_db, mx, ef, df);
      std::fflush(stdout);
    }
    ours.push_back(c);
  }
  for (const auto& [gv, preset] : configs) {
    codec::EncoderOptions o;
    o.lossless = true;
    o.intra_period = gop;
    o.intra_only = gop <= 1;
    o.geometry_modes = gv;
    o.preset = preset;
    double ef, df, mx;
    const RdPoint p = run_ours(m, o, &ef, &df, &mx);
    std::printf("| gvid lossless %s, gv %s | - | %.4f | %.2f | %.4f | %.1f | %.1f |\n",
                codec::preset_name(preset), gv ? "on" : "off", p.rate, p.psnr_db, mx, ef, df);
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
        std::printf("| %s | %d | %.4f | %.2f | %.3f | %.1f | %.1f |\n", c.name.c_str(), qp, p->rate,
                    p->psnr_db, mx, ef, df);
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
        std::printf("| %s | - | %.4f | %.2f | %.4f | %.1f | %.1f |\n", l.name.c_str(), p->rate,
                    p->psnr_db, mx, ef, df);
    }
  }
  std::printf("\n| BD-rate (piecewise cubic) | value |\n|---|---|\n");
  print_bd("geometry modes on vs off, fast preset", ours[1], ours[0]);
  if (slow) print_bd("geometry modes on vs off, slow preset (RDO)", ours[3], ours[2]);
  const Curve& best = slow ? ours[2] : ours[0];
  for (const Curve& p : peer_curves) print_bd(("gvid vs " + p.name).c_str(), p, best);
  return 0;
}
