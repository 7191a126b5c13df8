// surface_quality_compare: what a viewer sees of a decoded geometry video, measured beside the
// rate and the geometry PSNR: the normal-angle error (mean, 95th percentile, max, degrees, at
// the metric's normal scale) and the Hausdorff distance of the decoded surface to the input
// (all of it and at its outline), codec/surface_metrics.hpp. Sections:
//   --floor     the input's own normal noise: the input against itself lightly smoothed
//               (Gaussian sigma 0.5, 1, 2 px) and against near-lossless streams (0.02, 0.05,
//               0.1 mm bounds), at normal scales 0, 0.5, 1 and 2 px;
//   (default)   encoder configurations (--configs, default: all of the table below) at --qps,
//               one row per point, then BD-rates against "default" over PSNR and over the
//               normal error (quality axis -20 log10(p95 / 1 degree): monotone, and a halving
//               of the p95 counts as much at 4 degrees as at 1);
//   --peers     x265 12-bit 4:4:4 (I every --gop frames, IPBPB, ref 5, --peer-preset, tune psnr,
//               --peer-qps, default 0, 4, .., 24: libx265 takes no negative QP; and lossless;
//               the quantized planes given as Y, U, V) on the
//               same material, the BD-rates of ours against it over PSNR and over normal error, and
//               the rates of both at --target-p95 (interpolated between the points around it, log
//               rate over log p95).
// Usage: surface_quality_compare (--gv DIR | --ict DIR) [--frames N] [--qps Q1,Q2,..]
//                                [--preset slow|fast] [--configs NAME,NAME,..] [--floor]
//                                [--peers] [--peer-preset P] [--peer-qps Q1,..] [--gop N]
//                                [--target-p95 DEG]
//                                [--scale PX] [--write-decoded DIR] [--no-texture]
// (--write-decoded: every decoded point as DIR/CONFIG_qpQ/frame_NNNNNN.exr, to render;
// --no-texture: the frames' texture left out, so our streams code X, Y, Z only, as the peers do;
// without it our rate includes the texture plane of frames that have one.)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bd_rate.hpp"
#include "geometry_video_material.hpp"
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
namespace fs = std::filesystem;

struct Material {
  std::vector<GeometryImage> frames;
  SequenceInfo info;
  double vertices = 0, peak = 0;
};

// One point: rate, point error and surface error of a decoded sequence.
struct Point {
  double rate = 0;  // bits/vertex/frame
  GeometryError point;
  SurfaceError surface;
};

SurfaceErrorOptions g_metric;  // --scale
std::string g_write_dir;       // --write-decoded

Point measure(const Material& m, const std::vector<GeometryImage>& decoded, double bits,
              const std::string& write_name = "") {
  Point p;
  p.rate = bits / m.vertices / static_cast<double>(m.frames.size());
  for (size_t f = 0; f < m.frames.size(); ++f) {
    accumulate(p.point, geometry_error(m.frames[f], decoded[f]));
    accumulate(p.surface, surface_error(m.frames[f], decoded[f], g_metric));
  }
  if (!g_write_dir.empty() && !write_name.empty()) {
    const fs::path dir = fs::path(g_write_dir) / write_name;
    fs::create_directories(dir);
    for (size_t f = 0; f < decoded.size(); ++f)
      if (!write_geometry_image_exr(frame_path(dir, static_cast<int64_t>(f), ".exr"), decoded[f])
               .is_ok())
        std::fprintf(stderr, "cannot write %s\n", dir.c_str());
  }
  return p;
}

Point run_ours(const Material& m, const EncoderOptions& options, const std::string& write_name) {
  auto bytes = encode_gvid(m.frames, m.info, options);
  if (!bytes.is_ok()) {
    std::fprintf(stderr, "encode failed: %s\n", bytes.status().message().c_str());
    std::exit(1);
  }
  auto reader = GvidReader::open_memory(*bytes, "surface").value();
  std::vector<GeometryImage> decoded;
  double bits = 0;
  for (int64_t f = 0; f < reader->frame_count(); ++f) {
    decoded.push_back(reader->decode_frame(f).value());
    bits += static_cast<double>(reader->frame_bits(f));
  }
  return measure(m, decoded, bits, write_name);
}

void print_header(const char* what) {
  std::printf(
      "\n| %s | setting | bits/vertex/frame | PSNR (dB) | max error (mm) | normal error mean / p95 "
      "/ max (deg) | Hausdorff (mm) | outline Hausdorff (mm) | mean surface distance (mm) "
      "|\n|---|---|---|---|---|---|---|---|---|\n",
      what);
}

void print_row(const std::string& name, const std::string& setting, const Point& p,
               const Material& m) {
  std::printf("| %s | %s | %.4f | %.2f | %.3f | %.2f / %.2f / %.1f | %.3f | %.3f | %.4f |\n",
              name.c_str(), setting.c_str(), p.rate, p.point.psnr_db(m.peak), p.point.max_mm,
              p.surface.normal_mean_deg(), p.surface.normal_p95_deg(), p.surface.normal_max_deg,
              p.surface.hausdorff_mm, p.surface.outline_hausdorff_mm, p.surface.surface_mean_mm());
  std::fflush(stdout);
}

// The quality axes of the BD-rates: PSNR, and -20 log10(p95 / 1 degree) for the normal error.
std::vector<RdPoint> psnr_curve(const std::vector<Point>& points, const Material& m) {
  std::vector<RdPoint> c;
  for (const Point& p : points) c.push_back({p.rate, p.point.psnr_db(m.peak)});
  return c;
}
std::vector<RdPoint> normal_curve(const std::vector<Point>& points) {
  std::vector<RdPoint> c;
  for (const Point& p : points)
    c.push_back({p.rate, normal_quality_db(p.surface.normal_p95_deg())});
  return c;
}

// The rate at normal p95 = target, interpolated linearly in (log p95, log rate) between the two
// points around it (the points in any order); nothing when no two points bracket it.
std::optional<double> rate_at_p95(const std::vector<Point>& points, double target) {
  std::vector<Point> sorted = points;
  std::sort(sorted.begin(), sorted.end(),
            [](const Point& a, const Point& b) { return a.rate < b.rate; });
  for (size_t i = 0; i + 1 < sorted.size(); ++i) {
    const double p0 = sorted[i].surface.normal_p95_deg(),
                 p1 = sorted[i + 1].surface.normal_p95_deg();
    if ((p0 - target) * (p1 - target) > 0 || p0 == p1) continue;
    const double t = (std::log(target) - std::log(p0)) / (std::log(p1) - std::log(p0));
    return std::exp(std::log(sorted[i].rate) +
                    t * (std::log(sorted[i + 1].rate) - std::log(sorted[i].rate)));
  }
  return std::nullopt;
}

// Encoder configurations: the defaults and one suspect of ripples or notches changed each.
struct Config {
  std::string name;
  std::function<void(EncoderOptions&)> set;
};
std::vector<Config> all_configs() {
  return {
      {"default", [](EncoderOptions&) {}},
      {"no-deblock", [](EncoderOptions& o) { o.deblocking = false; }},
      {"deblock-strong",
       [](EncoderOptions& o) {
         o.deblock.beta *= 2;
         o.deblock.tc *= 2;
       }},
      {"deblock-weak",
       [](EncoderOptions& o) {
         o.deblock.beta = std::max(1, o.deblock.beta / 2);
         o.deblock.tc = std::max(1, o.deblock.tc / 2);
       }},
      {"full", [](EncoderOptions& o) { o.resolution = Resolution::kFull; }},
      {"half", [](EncoderOptions& o) { o.resolution = Resolution::kHalf; }},
      {"no-rdoq", [](EncoderOptions& o) { o.rdoq = false; }},
      {"xy+3",
       [](EncoderOptions& o) {
         o.plane_qp_offset[0] = 3;
         o.plane_qp_offset[1] = 3;
       }},
      {"xy+6",
       [](EncoderOptions& o) {
         o.plane_qp_offset[0] = 6;
         o.plane_qp_offset[1] = 6;
       }},
      {"z-3", [](EncoderOptions& o) { o.plane_qp_offset[2] = -3; }},
      {"z-6", [](EncoderOptions& o) { o.plane_qp_offset[2] = -6; }},
      {"xy+3z-3",
       [](EncoderOptions& o) {
         o.plane_qp_offset[0] = 3;
         o.plane_qp_offset[1] = 3;
         o.plane_qp_offset[2] = -3;
       }},
      {"bframes0", [](EncoderOptions& o) { o.bframes = 0; }},
      {"pqp0",
       [](EncoderOptions& o) {
         o.p_qp_offset = 0;
         o.b_qp_offset = 0;
       }},
      {"intra", [](EncoderOptions& o) { o.intra_only = true; }},
      {"transform4", [](EncoderOptions& o) { o.max_transform = 4; }},
      {"no-quadratic", [](EncoderOptions& o) { o.quadratic_intra = false; }},
      {"outline1", [](EncoderOptions& o) { o.outline_weight = 1; }},
      {"outline32", [](EncoderOptions& o) { o.outline_weight = 32; }},
  };
}

// The input against itself smoothed and against near-lossless streams, at several normal scales.
void report_floor(const Material& m, const EncoderOptions& base) {
  const double scales[4] = {0, 0.5, 1, 2};
  std::printf(
      "\n| reference vs | normal p95 (deg) at scale 0 / 0.5 / 1 / 2 px | normal mean (deg) at "
      "scale 0 / 0.5 / 1 / 2 px | max error (mm) | Hausdorff / outline (mm) | bits/vertex/frame "
      "|\n|---|---|---|---|---|---|\n");
  const auto row = [&](const std::string& name, const std::vector<GeometryImage>& other,
                       double rate) {
    double p95[4], mean[4], hausdorff = 0, outline = 0;
    GeometryError point;
    for (int s = 0; s < 4; ++s) {
      SurfaceErrorOptions o = g_metric;
      o.normal_scale_px = scales[s];
      SurfaceError total;
      for (size_t f = 0; f < m.frames.size(); ++f) {
        accumulate(total, surface_error(m.frames[f], other[f], o));
        if (s == 0) accumulate(point, geometry_error(m.frames[f], other[f]));
      }
      p95[s] = total.normal_p95_deg();
      hausdorff = total.hausdorff_mm;
      outline = total.outline_hausdorff_mm;
      mean[s] = total.normal_mean_deg();
    }
    char rate_text[32] = "-";
    if (rate > 0) std::snprintf(rate_text, sizeof rate_text, "%.4f", rate);
    std::printf(
        "| %s | %.2f / %.2f / %.2f / %.2f | %.2f / %.2f / %.2f / %.2f | %.4f | %.3f / %.3f | %s "
        "|\n",
        name.c_str(), p95[0], p95[1], p95[2], p95[3], mean[0], mean[1], mean[2], mean[3],
        point.max_mm, hausdorff, outline, rate_text);
    std::fflush(stdout);
  };
  for (double sigma : {0.5, 1.0, 2.0}) {
    std::vector<GeometryImage> smoothed;
    for (const GeometryImage& f : m.frames) {
      GeometryImage g = f;
      g.xyz_mm = smooth_positions(f.xyz_mm, surface_valid_pixels(f, f), sigma);
      smoothed.push_back(g);
    }
    char name[64];
    std::snprintf(name, sizeof name, "input smoothed, sigma %.1f px", sigma);
    row(name, smoothed, 0);
  }
  {  // the half-resolution path alone: halved by the encoder, upsampled by the decoder's filter
    std::vector<GeometryImage> resampled;
    for (size_t f = 0; f < m.frames.size(); ++f) {
      std::vector<SamplePlane> planes = quantize_geometry(m.frames[f], m.info);
      for (SamplePlane& p : planes)
        p = upsample_half_plane(downsample_plane(p, m.info.width, m.info.height, 16), m.info.width,
                                m.info.height, 16);
      resampled.push_back(dequantize_geometry(planes, m.info, static_cast<int64_t>(f)));
    }
    row("half resolution without coding (halved, upsampled)", resampled, 0);
  }
  for (double bound : {0.02, 0.05, 0.1}) {
    EncoderOptions o = base;
    o.max_error_mm = bound;
    auto bytes = encode_gvid(m.frames, m.info, o).value();
    auto reader = GvidReader::open_memory(bytes, "floor").value();
    std::vector<GeometryImage> decoded;
    double bits = 0;
    for (int64_t f = 0; f < reader->frame_count(); ++f) {
      decoded.push_back(reader->decode_frame(f).value());
      bits += static_cast<double>(reader->frame_bits(f));
    }
    char name[64];
    std::snprintf(name, sizeof name, "near-lossless, --max-error-mm %.2f", bound);
    row(name, decoded, bits / m.vertices / static_cast<double>(m.frames.size()));
  }
}

// x265 12-bit 4:4:4 at each QP (libx265 takes 0..51: a negative qp crashes it), then lossless
// (its point goes to *lossless, not into the curve).
std::vector<Point> run_x265(const Material& m, int gop, const std::string& preset,
                            const std::vector<int>& qps, Point* lossless) {
  std::vector<Point> points;
  print_header("peer");
  std::fflush(stdout);
  std::vector<std::vector<SamplePlane>> planes;
  SequenceInfo info = m.info;
  info.bit_depth = 12;
  for (const GeometryImage& f : m.frames) planes.push_back(quantize_geometry(f, info));
  const std::string name = "x265 12-bit 4:4:4, I" + std::to_string(gop) + " IPBPB ref 5, " + preset;
  const auto run = [&](const std::string& params,
                       const std::string& label) -> std::optional<Point> {
    PeerConfig c{"libx265", "yuv444p12le", 12, {{"preset", preset}, {"tune", "psnr"}}};
    c.gop = gop;
    c.bframes = 1;
    c.options.push_back({"x265-params", "log-level=error:keyint=" + std::to_string(gop) +
                                            ":bframes=1:ref=5:" + params});
    auto r = run_peer(planes, info.width, info.height, c);
    if (!r.is_ok()) {
      std::fprintf(stderr, "%s\n", r.status().message().c_str());
      return std::nullopt;
    }
    std::vector<GeometryImage> decoded;
    double bits = 0;
    for (size_t f = 0; f < m.frames.size(); ++f) {
      decoded.push_back(dequantize_geometry(r->decoded[f], info, static_cast<int64_t>(f)));
      bits += 8.0 * static_cast<double>(r->frame_bytes[f]);
    }
    const Point p = measure(m, decoded, bits, "x265_" + label);
    print_row(name, label, p, m);
    return p;
  };
  for (int qp : qps) {
    if (qp < 0) {
      std::fprintf(stderr, "x265: qp %d skipped (libx265 takes 0..51)\n", qp);
      continue;
    }
    const auto p = run("qp=" + std::to_string(qp), "qp " + std::to_string(qp));
    if (!p) break;
    points.push_back(*p);
  }
  if (const auto p = run("lossless=1", "lossless")) *lossless = *p;
  return points;
}

std::vector<int> parse_ints(const std::string& s) {
  std::vector<int> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(std::stoi(item));
  return out;
}
std::vector<std::string> parse_names(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(item);
  return out;
}

int run(int argc, char** argv) {
  std::string gv_dir, ict_dir, preset = "slow", peer_preset = "slower";
  std::vector<int> qps = {0, 6, 12, 18}, peer_qps = {0, 4, 8, 12, 16, 20, 24};
  std::vector<std::string> config_names;
  bool floor = false, peers = false, no_texture = false;
  int frames = 0, gop = 30;
  double target_p95 = 2.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool more = i + 1 < argc;
    if (a == "--gv" && more)
      gv_dir = argv[++i];
    else if (a == "--ict" && more)
      ict_dir = argv[++i];
    else if (a == "--frames" && more)
      frames = std::atoi(argv[++i]);
    else if (a == "--qps" && more)
      qps = parse_ints(argv[++i]);
    else if (a == "--preset" && more)
      preset = argv[++i];
    else if (a == "--configs" && more)
      config_names = parse_names(argv[++i]);
    else if (a == "--floor")
      floor = true;
    else if (a == "--no-texture")
      no_texture = true;
    else if (a == "--peers")
      peers = true;
    else if (a == "--peer-qps" && more)
      peer_qps = parse_ints(argv[++i]);
    else if (a == "--peer-preset" && more)
      peer_preset = argv[++i];
    else if (a == "--gop" && more)
      gop = std::atoi(argv[++i]);
    else if (a == "--target-p95" && more)
      target_p95 = std::atof(argv[++i]);
    else if (a == "--scale" && more)
      g_metric.normal_scale_px = std::atof(argv[++i]);
    else if (a == "--write-decoded" && more)
      g_write_dir = argv[++i];
    else {
      std::fprintf(stderr,
                   "usage: surface_quality_compare (--gv DIR | --ict DIR) [--frames N] "
                   "[--qps Q1,Q2,..] [--preset slow|fast] [--configs NAME,..] [--floor] "
                   "[--peers] [--peer-preset P] [--peer-qps Q1,..] [--gop N] [--target-p95 DEG] "
                   "[--scale PX] [--write-decoded DIR] [--no-texture]\n");
      return 2;
    }
  }
  if (!g_metric.check().is_ok()) {
    std::fprintf(stderr, "--scale: %s\n", g_metric.check().message().c_str());
    return 2;
  }
  Material m;
  if (!gv_dir.empty()) {
    auto files = list_frame_files(gv_dir, ".exr");
    if (!files.is_ok() || files->empty()) {
      std::fprintf(stderr, "%s: no frame_NNNNNN.exr files\n", gv_dir.c_str());
      return 1;
    }
    for (const auto& f : *files) {
      if (frames > 0 && static_cast<int>(m.frames.size()) >= frames) break;
      auto image = read_geometry_image_exr(f.path);
      if (!image.is_ok()) {
        std::fprintf(stderr, "%s\n", image.status().message().c_str());
        return 1;
      }
      m.frames.push_back(std::move(image).value());
    }
  } else if (!ict_dir.empty()) {
    testing::GeometryVideoOptions vo;
    vo.frames = frames > 0 ? frames : 30;
    auto video = testing::make_ict_face_video(ict_dir, vo);
    if (!video.is_ok()) {
      std::fprintf(stderr, "%s\n", video.status().message().c_str());
      return 1;
    }
    m.frames = std::move(video).value();
  } else {
    std::fprintf(stderr, "give --gv DIR or --ict DIR\n");
    return 2;
  }
  if (no_texture)  // geometry only, as the peers code it
    for (GeometryImage& f : m.frames) f.texture = cv::Mat();
  m.info = make_sequence_info(m.frames, 16, 30.0).value();
  m.vertices = static_cast<double>(m.info.domain_pixels());
  m.peak = m.info.box_diagonal_mm();
  EncoderOptions base;
  base.preset = parse_preset(preset).value();
  base.intra_period = gop;
  std::printf(
      "material: %s, %dx%d, %zu frames, %.0f domain pixels, diagonal %.1f mm; %s preset, I "
      "frame every %d; normal scale %.2g px, Hausdorff window %d px%s\n",
      gv_dir.empty() ? "ICT face in its UV layout" : gv_dir.c_str(), m.info.width, m.info.height,
      m.frames.size(), m.vertices, m.peak, preset.c_str(), gop, g_metric.normal_scale_px,
      g_metric.window_px,
      m.info.has_texture ? "; our rate includes the texture plane" : "; geometry only");

  if (floor) report_floor(m, base);

  std::vector<Config> configs;
  for (const Config& c : all_configs())
    if (config_names.empty() ||
        std::find(config_names.begin(), config_names.end(), c.name) != config_names.end())
      configs.push_back(c);
  std::vector<std::vector<Point>> curves;
  if (!qps.empty() && !configs.empty()) {
    print_header("configuration");
    for (const Config& c : configs) {
      std::vector<Point> curve;
      for (int qp : qps) {
        EncoderOptions o = base;
        o.qp = qp;
        c.set(o);
        curve.push_back(run_ours(m, o, c.name + "_qp" + std::to_string(qp)));
        print_row(c.name, "qp " + std::to_string(qp), curve.back(), m);
      }
      curves.push_back(curve);
    }
    if (configs[0].name == "default" && configs.size() > 1) {
      std::printf(
          "\n| BD-rate against default (piecewise cubic) | over PSNR | over normal error "
          "|\n|---|---|---|\n");
      for (size_t i = 1; i < configs.size(); ++i) {
        const auto bd_psnr = bd_rate_percent(psnr_curve(curves[0], m), psnr_curve(curves[i], m));
        const auto bd_normal = bd_rate_percent(normal_curve(curves[0]), normal_curve(curves[i]));
        std::printf("| %s | %s | %s |\n", configs[i].name.c_str(),
                    bd_psnr ? (std::to_string(*bd_psnr).substr(0, 6) + " %").c_str() : "-",
                    bd_normal ? (std::to_string(*bd_normal).substr(0, 6) + " %").c_str() : "-");
      }
    }
  }
  if (peers) {
    Point x265_lossless;
    const std::vector<Point> x265 = run_x265(m, gop, peer_preset, peer_qps, &x265_lossless);
    std::printf(
        "\n| against x265 12-bit (piecewise cubic) | BD-rate over PSNR | over normal "
        "error | bits/vertex/frame at normal p95 %.2g deg: ours / x265 |\n|---|---|---|---|\n",
        target_p95);
    for (size_t i = 0; i < curves.size(); ++i) {
      const auto bd_psnr = bd_rate_percent(psnr_curve(x265, m), psnr_curve(curves[i], m));
      const auto bd_normal = bd_rate_percent(normal_curve(x265), normal_curve(curves[i]));
      const auto ours = rate_at_p95(curves[i], target_p95), theirs = rate_at_p95(x265, target_p95);
      char at[96] = "outside the curves";
      if (ours && theirs) std::snprintf(at, sizeof at, "%.4f / %.4f", *ours, *theirs);
      std::printf("| %s | %s | %s | %s |\n", configs[i].name.c_str(),
                  bd_psnr ? (std::to_string(*bd_psnr).substr(0, 6) + " %").c_str() : "-",
                  bd_normal ? (std::to_string(*bd_normal).substr(0, 6) + " %").c_str() : "-", at);
    }
    if (x265_lossless.rate > 0)
      std::printf("\nx265 12-bit lossless: %.4f bits/vertex/frame at normal p95 %.2f deg\n",
                  x265_lossless.rate, x265_lossless.surface.normal_p95_deg());
  }
  return 0;
}

}  // namespace
}  // namespace gvkit::bench

int main(int argc, char** argv) { return gvkit::bench::run(argc, argv); }
