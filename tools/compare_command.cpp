// gvkit compare REFERENCE DECODED [-o OUT.mp4] [--contact-sheet OUT.png]: a decoded geometry
// video beside its input. Per frame: the point error (PSNR, RMS, max) and the surface error
// (normal-angle error mean / p95 / max, Hausdorff distance, codec/surface_metrics.hpp) into
// stats.json (PSNR peak: the first reference frame's bounding-box diagonal); with -o or
// --contact-sheet also the picture input | decoded | normal-error heat map (Turbo, degrees),
// rendered offscreen from one camera, as an MP4 and a contact sheet (one row per chosen frame).
// Each frame is read and measured on a worker while the one before it is drawn.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "command.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/surface_metrics.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/log.hpp"
#include "gvkit/core/progress.hpp"
#include "gvkit/player/contact_sheet.hpp"
#include "gvkit/player/frame_range.hpp"
#include "gvkit/player/frame_sequence.hpp"
#include "gvkit/player/geometry_image_mesh.hpp"
#include "gvkit/player/renderer.hpp"
#include "surface_error_json.hpp"
#include "tool_support.hpp"
#include "video_file.hpp"

namespace gvkit::tools {
namespace {
namespace fs = std::filesystem;
using namespace gvkit::player;

struct CompareOptions {
  std::string reference, decoded, output, contact_sheet, stats;
  std::string view = "front", size = "640x480", frames = ":";
  std::string heat = "normal";   // what the heat map shows: normal (degrees) or distance (mm)
  double normal_max_deg = 5.0;   // top of the heat map's colour scale (normal)
  double distance_max_mm = 1.0;  // top of the heat map's colour scale (distance)
  double zoom = 1.0;             // < 1 comes closer
  std::vector<double> pan;       // empty, or (dx, dy) in units of the scene radius
  double fps = 0;                // 0 = the reference's
  int contact_frames = 4, msaa = 4;
  codec::SurfaceErrorOptions metric;
};

nlohmann::json psnr_json(double psnr) {
  return std::isfinite(psnr) ? nlohmann::json(psnr) : nlohmann::json("inf");
}

// The normal error of each vertex of mesh (degrees; NaN where undefined), from the per-pixel
// angles.
std::vector<float> vertex_values(const MeshBuffers& mesh, const cv::Mat& per_pixel) {
  std::vector<float> out(mesh.vertex_count());
  for (size_t i = 0; i < out.size(); ++i) {
    const int p = mesh.pixel_index[i];
    out[i] = per_pixel.at<float>(p / per_pixel.cols, p % per_pixel.cols);
  }
  return out;
}

void put_label(cv::Mat& picture, const std::string& text) {
  const double scale = std::clamp(picture.rows / 600.0, 0.35, 0.8);
  cv::putText(picture, text, {8, picture.rows - 12}, cv::FONT_HERSHEY_SIMPLEX, scale,
              cv::Scalar(30, 30, 30), 1, cv::LINE_AA);
}

void run_compare(const CompareOptions& o) {
  throw_if_error(o.metric.check());
  if (!(o.normal_max_deg > 0)) throw CommandFailed(invalid_argument("--normal-max must be > 0"));
  if (!(o.distance_max_mm > 0)) throw CommandFailed(invalid_argument("--distance-max must be > 0"));
  if (o.heat != "normal" && o.heat != "distance")
    throw CommandFailed(invalid_argument("--heat '" + o.heat + "' unknown (normal or distance)"));
  const bool distance_heat = o.heat == "distance";
  if (!(o.zoom > 0)) throw CommandFailed(invalid_argument("--zoom must be > 0"));
  if (o.fps < 0) throw CommandFailed(invalid_argument("--fps must be > 0"));
  if (o.contact_frames < 1) throw CommandFailed(invalid_argument("--contact-frames must be >= 1"));
  const bool pictures = !o.output.empty() || !o.contact_sheet.empty();
  RenderOptions render_options;
  render_options.msaa_samples = o.msaa;
  std::tie(render_options.width, render_options.height) = value_or_throw(parse_size(o.size));
  throw_if_error(render_options.check());
  if (!o.output.empty() && (render_options.width % 2 || render_options.height % 2))
    throw CommandFailed(invalid_argument("--size: MP4 needs an even width and height"));
  const ViewPreset view = value_or_throw(parse_view_preset(o.view));
  if (!o.pan.empty() && o.pan.size() != 2)
    throw CommandFailed(invalid_argument("--pan: give two values (DX DY)"));
  const bool pan_set = o.pan.size() == 2;

  auto reference = value_or_throw(FrameSequence::create(o.reference));
  auto decoded = value_or_throw(FrameSequence::create(o.decoded));
  if (decoded->frame_count() != reference->frame_count())
    throw CommandFailed(invalid_argument(o.decoded + ": " + std::to_string(decoded->frame_count()) +
                                         " frames, the reference " + o.reference + " has " +
                                         std::to_string(reference->frame_count())));
  const std::vector<int64_t> indices =
      value_or_throw(value_or_throw(parse_frame_range(o.frames)).indices(reference->frame_count()));
  const double fps = o.fps > 0 ? o.fps : reference->fps();
  std::unique_ptr<Renderer> renderer;
  if (pictures) renderer = value_or_throw(Renderer::create(render_options));

  const std::vector<size_t> sheet_positions = evenly_spaced(indices.size(), o.contact_frames);
  std::vector<cv::Mat> sheet_tiles;
  std::vector<std::string> sheet_labels;
  opencv_media::VideoWriter writer;
  std::string video_codec;
  std::unique_ptr<ViewCamera> camera;
  codec::GeometryError point_total;
  codec::SurfaceError surface_total;
  double peak = 0;
  nlohmann::json per_frame = nlohmann::json::array();
  Progress progress("compare", static_cast<int64_t>(indices.size()));
  // Frame k + 1 is read and measured (and its heat values computed) on a worker while frame k
  // is drawn here: the renderer's OpenGL context stays on this thread.
  struct Measured {
    int64_t index = 0;
    GeometryImage a, b;
    codec::GeometryError e;
    codec::SurfaceError s;
    cv::Mat heat;  // per pixel: normal error (deg) or distance (mm); with pictures only
  };
  const auto measure = [&](size_t k) {
    Measured m;
    m.index = indices[k];
    const int64_t i = m.index;
    m.a = value_or_throw(reference->frame(i));
    m.b = value_or_throw(decoded->frame(i));
    const GeometryImage& a = m.a;
    const GeometryImage& b = m.b;
    if (a.size() != b.size())
      throw CommandFailed(invalid_argument(
          o.decoded + ": frame " + std::to_string(i) + " is " + std::to_string(b.size().width) +
          "x" + std::to_string(b.size().height) + ", the reference's " +
          std::to_string(a.size().width) + "x" + std::to_string(a.size().height)));
    throw_if_error(a.check().with_context(o.reference + ": frame " + std::to_string(i)));
    m.e = codec::geometry_error(a, b);
    m.s = codec::surface_error(a, b, o.metric);
    if (pictures)
      m.heat = distance_heat ? codec::surface_distance_mm(a, b, o.metric)
                             : codec::normal_error_deg(a, b, o.metric);
    return m;
  };
  std::future<Measured> next;
  if (!indices.empty()) next = std::async(std::launch::async, measure, size_t{0});
  for (size_t k = 0; k < indices.size(); ++k, progress.advance()) {
    Measured m = next.get();
    if (k + 1 < indices.size()) next = std::async(std::launch::async, measure, k + 1);
    const int64_t i = m.index;
    const GeometryImage& a = m.a;
    const GeometryImage& b = m.b;
    if (peak == 0) {  // PSNR peak: the first frame's box diagonal over its domain
      cv::Vec3f lo(1e30f, 1e30f, 1e30f), hi(-1e30f, -1e30f, -1e30f);
      for (int y = 0; y < a.xyz_mm.rows; ++y)
        for (int x = 0; x < a.xyz_mm.cols; ++x)
          if (a.domain_mask.at<uint8_t>(y, x))
            for (int c = 0; c < 3; ++c) {
              lo[c] = std::min(lo[c], a.xyz_mm.at<cv::Vec3f>(y, x)[c]);
              hi[c] = std::max(hi[c], a.xyz_mm.at<cv::Vec3f>(y, x)[c]);
            }
      peak = cv::norm(hi - lo);
    }
    const codec::GeometryError& e = m.e;
    const codec::SurfaceError& s = m.s;
    codec::accumulate(point_total, e);
    codec::accumulate(surface_total, s);
    nlohmann::json fj = {{"index", i},
                         {"psnr_db", psnr_json(e.psnr_db(peak))},
                         {"rms_mm", e.rms_mm},
                         {"max_mm", e.max_mm}};
    fj.update(surface_error_json(s));
    per_frame.push_back(fj);
    if (!pictures) continue;

    const MeshBuffers mesh_a = mesh_buffers_from_geometry_image(a);
    const MeshBuffers mesh_b = mesh_buffers_from_geometry_image(b);
    if (!camera) camera = std::make_unique<ViewCamera>(scene_frame(mesh_a));
    camera->set_preset(view,
                       indices.size() > 1 ? static_cast<double>(k) / (indices.size() - 1) : 0.0);
    camera->zoom(o.zoom);
    if (pan_set) camera->pan(o.pan[0], o.pan[1]);
    DrawStyle lit;
    renderer->set_mesh(mesh_a);
    cv::Mat left = value_or_throw(renderer->render(*camera, lit));
    renderer->set_mesh(mesh_b);
    cv::Mat middle = value_or_throw(renderer->render(*camera, lit));
    DrawStyle heat;
    heat.mode = ShadingMode::kError;
    renderer->set_vertex_errors(vertex_values(mesh_b, m.heat));
    if (distance_heat) {
      heat.error_max_mm = static_cast<float>(o.distance_max_mm);
      heat.error_title = "distance to input (mm)";
    } else {
      heat.error_max_mm = static_cast<float>(o.normal_max_deg);
      heat.error_title = "normal error (deg)";
    }
    cv::Mat right = value_or_throw(renderer->render(*camera, heat));
    char text[160];
    put_label(left, "input");
    std::snprintf(text, sizeof text, "decoded: %.1f dB, max %.2f mm", e.psnr_db(peak), e.max_mm);
    put_label(middle, text);
    std::snprintf(text, sizeof text, "normal p95 %.2f deg, H %.2f mm", s.normal_p95_deg(),
                  s.hausdorff_mm);
    put_label(right, text);
    cv::Mat row;
    cv::hconcat(std::vector<cv::Mat>{left, middle, right}, row);
    if (!o.output.empty()) {
      if (!writer.is_open())
        video_codec = value_or_throw(open_video(writer, o.output, fps, row.size()));
      throw_if_error(writer.write(row));
    }
    if (std::find(sheet_positions.begin(), sheet_positions.end(), k) != sheet_positions.end()) {
      for (const cv::Mat* tile : {&left, &middle, &right}) sheet_tiles.push_back(*tile);
      const std::string f = "frame " + std::to_string(i);
      sheet_labels.insert(sheet_labels.end(), {f, f, f});
    }
  }
  progress.finish();
  writer.release();
  if (!o.contact_sheet.empty() && !sheet_tiles.empty())
    throw_if_error(write_image(o.contact_sheet, contact_sheet(sheet_tiles, sheet_labels, 3)));

  nlohmann::json summary = {{"frames", indices.size()},
                            {"psnr_db", psnr_json(point_total.psnr_db(peak))},
                            {"peak_mm", peak},
                            {"rms_mm", point_total.rms_mm},
                            {"max_mm", point_total.max_mm}};
  summary.update(surface_error_json(surface_total));
  if (!video_codec.empty()) summary["video_codec"] = video_codec;
  const nlohmann::json stats = {{"reference", o.reference},
                                {"decoded", o.decoded},
                                {"summary", summary},
                                {"frames", per_frame},
                                {"options",
                                 {{"frames", o.frames},
                                  {"normal_scale_px", o.metric.normal_scale_px},
                                  {"hausdorff_window_px", o.metric.window_px},
                                  {"heat", o.heat},
                                  {"normal_max_deg", o.normal_max_deg},
                                  {"distance_max_mm", o.distance_max_mm},
                                  {"view", o.view},
                                  {"size", o.size},
                                  {"zoom", o.zoom},
                                  {"pan", o.pan},
                                  {"output", o.output},
                                  {"contact_sheet", o.contact_sheet}}}};
  fs::path stats_path = o.stats;
  if (stats_path.empty() && !o.output.empty())
    stats_path = fs::path(o.output).replace_extension(".stats.json");
  else if (stats_path.empty() && !o.contact_sheet.empty())
    stats_path = fs::path(o.contact_sheet).replace_extension(".stats.json");
  if (!stats_path.empty()) throw_if_error(write_json(stats_path, stats));
  std::printf(
      "%s vs %s: %zu frames, PSNR %.2f dB, max %.4g mm, normal error mean %.2f / p95 %.2f / max "
      "%.1f deg (scale %.3g px), Hausdorff %.4g mm (outline %.4g mm)\n",
      o.decoded.c_str(), o.reference.c_str(), indices.size(), point_total.psnr_db(peak),
      point_total.max_mm, surface_total.normal_mean_deg(), surface_total.normal_p95_deg(),
      surface_total.normal_max_deg, o.metric.normal_scale_px, surface_total.hausdorff_mm,
      surface_total.outline_hausdorff_mm);
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  auto* cmd = app.add_subcommand(
      "compare",
      "A decoded geometry video beside its input: point and surface error (normal-angle error, "
      "Hausdorff distance) per frame, and pictures input | decoded | normal-error heat map");
  cmd->add_option("reference", o->reference, "The input: FILE.gvid or a folder of frame_NNNNNN.exr")
      ->required();
  cmd->add_option("decoded", o->decoded, "The decoded video: FILE.gvid or a folder of EXRs")
      ->required();
  cmd->add_option("-o,--output", o->output, "OUT.mp4: the three pictures side by side per frame");
  cmd->add_option("--contact-sheet", o->contact_sheet,
                  "OUT.png: one row (input | decoded | heat map) per chosen frame");
  cmd->add_option("--stats", o->stats,
                  "Where stats.json goes (default: beside -o, else beside --contact-sheet; none "
                  "without either)");
  cmd->add_option("--frames", o->frames, "Frames A:B (half-open), A:, :B or N")
      ->capture_default_str();
  cmd->add_option("--contact-frames", o->contact_frames, "Rows of the contact sheet")
      ->capture_default_str();
  cmd->add_option("--normal-max", o->normal_max_deg,
                  "Top of the heat map's colour scale (degrees of normal error)")
      ->capture_default_str();
  cmd->add_option("--heat", o->heat,
                  "What the heat map shows: normal (normal-angle error, degrees) or distance "
                  "(each decoded vertex's distance to the input surface, mm)")
      ->capture_default_str();
  cmd->add_option("--distance-max", o->distance_max_mm,
                  "Top of the heat map's colour scale with --heat distance (mm)")
      ->capture_default_str();
  cmd->add_option("--normal-scale", o->metric.normal_scale_px,
                  "Normals compared after a Gaussian smoothing of this sigma (pixels) of both "
                  "surfaces; 0 = raw per-pixel normals")
      ->capture_default_str();
  cmd->add_option("--hausdorff-window", o->metric.window_px,
                  "Nearest points searched within this many pixels (1..16)")
      ->capture_default_str();
  cmd->add_option("--view", o->view, "front, left, right or orbit")->capture_default_str();
  cmd->add_option("--zoom", o->zoom, "Camera distance factor (< 1 comes closer)")
      ->capture_default_str();
  cmd->add_option("--pan", o->pan,
                  "Camera pan DX DY in units of the face's radius (right, up), e.g. for a close-up "
                  "with --zoom")
      ->expected(2);
  cmd->add_option("--size", o->size, "Size WxH (px) of each of the three pictures")
      ->capture_default_str();
  cmd->add_option("--fps", o->fps, "MP4 frame rate (default: the reference's)");
  cmd->add_option("--msaa", o->msaa, "Multisample anti-aliasing samples (0..16)")
      ->capture_default_str();
  cmd->callback([o] { run_compare(*o); });
}

}  // namespace gvkit::tools
