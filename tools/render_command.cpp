// gvkit render INPUT -o OUT.mp4 | OUT_DIR: draws a geometry video offscreen (EGL, no display
// needed) into an MP4 or a folder of PNG frames, and optionally a contact sheet. Frames are
// decoded and meshed ahead on a worker (FramePrefetcher) and encoded behind on another
// (PictureWriter) while the calling thread draws.
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gvkit/core/file_extension.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/log.hpp"
#include "gvkit/core/progress.hpp"
#include "gvkit/player/contact_sheet.hpp"
#include "gvkit/player/frame_prefetcher.hpp"
#include "gvkit/player/frame_range.hpp"
#include "gvkit/player/frame_sequence.hpp"
#include "gvkit/player/geometry_error.hpp"
#include "gvkit/player/mesh_level_of_detail.hpp"
#include "gvkit/player/renderer.hpp"
#include "tool_support.hpp"
#include "video_file.hpp"

namespace gvkit::tools {
namespace {
namespace fs = std::filesystem;
using namespace gvkit::player;

struct RenderCommandOptions {
  std::string input, output, reference, contact_sheet;
  std::string view = "front", size = "640x480", shading = "lit", frames = ":";
  double fps = 0;           // 0 = the sequence's
  double error_max_mm = 0;  // 0 = automatic (99th percentile of the first frame's errors)
  int contact_frames = 8, contact_columns = 4, msaa = 4;
  std::string mesh_stride = "auto";  // or 1..16
};

bool is_video_path(const fs::path& p) {
  const std::string ext = lower_extension(p);
  return ext == ".mp4" || ext == ".mkv" || ext == ".avi";
}

float percentile(std::vector<float> values, double q) {
  values.erase(std::remove_if(values.begin(), values.end(), [](float v) { return !(v >= 0); }),
               values.end());
  if (values.empty()) return 0;
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(q * values.size()));
  std::nth_element(values.begin(), values.begin() + static_cast<ptrdiff_t>(k), values.end());
  return values[k];
}

// Encodes the rendered pictures (MP4 through FFmpeg, or PNG files) on a thread of its own, so
// that the next frame is drawn meanwhile; at most `capacity` pictures wait. The first failure
// is kept and returned by finish().
class PictureWriter {
 public:
  explicit PictureWriter(size_t capacity) : capacity_(capacity), thread_([this] { run(); }) {}
  ~PictureWriter() { static_cast<void>(finish()); }

  void push(std::function<Status()> write) {
    std::unique_lock<std::mutex> lock(mutex_);
    space_.wait(lock, [&] { return jobs_.size() < capacity_; });
    jobs_.push_back(std::move(write));
    ready_.notify_one();
  }
  Status finish() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
    if (thread_.joinable()) thread_.join();
    return status_;
  }

 private:
  void run() {
    for (;;) {
      std::function<Status()> job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait(lock, [&] { return closed_ || !jobs_.empty(); });
        if (jobs_.empty()) return;
        job = std::move(jobs_.front());
        jobs_.pop_front();
        space_.notify_one();
      }
      Status s = status_.is_ok() ? job() : Status::ok();
      if (!s.is_ok()) status_ = s;
    }
  }

  size_t capacity_;
  std::mutex mutex_;
  std::condition_variable ready_, space_;
  std::deque<std::function<Status()>> jobs_;
  bool closed_ = false;
  Status status_ = Status::ok();
  std::thread thread_;
};

void run_render(const RenderCommandOptions& o) {
  if (o.output.empty() && o.contact_sheet.empty())
    throw CommandFailed(invalid_argument("render: give -o OUT.mp4|OUT_DIR and/or --contact-sheet"));
  RenderOptions render_options;
  render_options.msaa_samples = o.msaa;
  std::tie(render_options.width, render_options.height) = value_or_throw(parse_size(o.size));
  throw_if_error(render_options.check());
  const ViewPreset view = value_or_throw(parse_view_preset(o.view));
  DrawStyle style;
  style.mode = value_or_throw(parse_shading_mode(o.shading));
  if (o.error_max_mm < 0) throw CommandFailed(invalid_argument("--error-max must be >= 0"));
  if (o.contact_frames < 1 || o.contact_columns < 1)
    throw CommandFailed(invalid_argument("--contact-frames and --contact-columns must be >= 1"));
  GeometryImageMeshOptions mesh_options;
  const bool auto_stride = o.mesh_stride == "auto";
  if (!auto_stride) {
    try {
      size_t used = 0;
      mesh_options.stride = std::stoi(o.mesh_stride, &used);
      if (used != o.mesh_stride.size()) throw std::invalid_argument(o.mesh_stride);
    } catch (const std::exception&) {
      throw CommandFailed(
          invalid_argument("--mesh-stride must be auto or 1..16, got '" + o.mesh_stride + "'"));
    }
  }
  throw_if_error(mesh_options.check());
  if (o.fps < 0) throw CommandFailed(invalid_argument("--fps must be > 0"));
  const bool video = !o.output.empty() && is_video_path(o.output);
  if (video && (render_options.width % 2 || render_options.height % 2))
    throw CommandFailed(invalid_argument("--size: MP4 needs an even width and height"));
  if (style.mode == ShadingMode::kError && o.reference.empty())
    throw CommandFailed(invalid_argument("--shading error needs --reference"));

  std::shared_ptr<FrameSequence> seq = value_or_throw(FrameSequence::create(o.input));
  std::unique_ptr<FrameSequence> ref;
  if (!o.reference.empty()) ref = value_or_throw(FrameSequence::create(o.reference));
  const std::vector<int64_t> indices =
      value_or_throw(value_or_throw(parse_frame_range(o.frames)).indices(seq->frame_count()));
  const double fps = o.fps > 0 ? o.fps : seq->fps();
  auto renderer = value_or_throw(Renderer::create(render_options));
  logger().info("render: {} -> {} frames with {}", seq->name(), indices.size(),
                renderer->description());

  std::unique_ptr<ViewCamera> camera;
  if (auto_stride && !indices.empty()) {
    // The first frame at full detail frames the camera (as every stride-1 render does), and its
    // grid step in the picture sets the stride for the whole video.
    auto first = seq->frame(indices.front());
    if (first.is_ok()) {
      const MeshBuffers full = mesh_buffers_from_geometry_image(*first);
      camera = std::make_unique<ViewCamera>(scene_frame(full));
      camera->set_preset(view, 0.0);
      mesh_options.stride =
          auto_mesh_stride(full, *camera, render_options.width, render_options.height);
      logger().info(
          "render: mesh stride {} (grid step {:.2f} px at full detail)", mesh_options.stride,
          projected_grid_step_px(full, *camera, render_options.width, render_options.height));
    }
  }
  PrefetchOptions prefetch;
  prefetch.loop = false;
  prefetch.mesh.stride = mesh_options.stride;
  FramePrefetcher frames(seq, prefetch);
  if (!o.output.empty() && !video) throw_if_error(ensure_directory(o.output));
  opencv_media::VideoWriter writer;
  std::string codec;
  if (video) {  // opened here: the writer thread only writes
    const cv::Size picture_size(render_options.width, render_options.height);
    codec = value_or_throw(open_video(writer, o.output, fps, picture_size));
  }
  PictureWriter picture_writer(4);
  const std::vector<size_t> sheet_positions = evenly_spaced(indices.size(), o.contact_frames);
  std::vector<cv::Mat> sheet_tiles;
  std::vector<std::string> sheet_labels;
  std::vector<std::string> failures;
  nlohmann::json per_frame = nlohmann::json::array();
  float error_max = static_cast<float>(o.error_max_mm);
  Progress progress("render", static_cast<int64_t>(indices.size()));
  const auto start = std::chrono::steady_clock::now();
  int64_t rendered = 0;

  for (size_t k = 0; k < indices.size(); ++k, progress.advance()) {
    const int64_t i = indices[k];
    auto frame = frames.get(i);
    if (!frame->status.is_ok()) {
      logger().warn("frame {}: {}", i, frame->status.message());
      failures.push_back(frame->status.message());
      continue;
    }
    nlohmann::json fj = {{"index", i},
                         {"vertices", frame->mesh.vertex_count()},
                         {"triangles", frame->mesh.triangle_count()}};
    renderer->set_mesh(frame->mesh);
    if (ref) {
      if (i >= ref->frame_count()) {
        failures.push_back("reference has no frame " + std::to_string(i));
        continue;
      }
      auto ref_frame = ref->frame(i);
      if (!ref_frame.is_ok()) {
        failures.push_back("reference: " + ref_frame.status().message());
        continue;
      }
      auto errors = vertex_errors_mm(frame->mesh, *ref_frame);
      auto stats = geometry_error(frame->image, *ref_frame);
      if (!errors.is_ok() || !stats.is_ok()) {
        const Status& s = errors.is_ok() ? stats.status() : errors.status();
        failures.push_back("frame " + std::to_string(i) + " vs reference: " + s.message());
        continue;
      }
      if (error_max <= 0) error_max = std::max(1e-3f, percentile(*errors, 0.99));
      renderer->set_vertex_errors(*errors);
      fj["rms_mm"] = stats->rms_mm;
      fj["max_mm"] = stats->max_mm;
      fj["psnr_db"] =
          std::isfinite(stats->psnr_db) ? nlohmann::json(stats->psnr_db) : nlohmann::json("inf");
    }
    style.error_max_mm = error_max > 0 ? error_max : 1.0f;
    if (!camera) camera = std::make_unique<ViewCamera>(scene_frame(frame->mesh));
    const double phase = indices.size() > 1 ? static_cast<double>(k) / (indices.size() - 1) : 0.0;
    camera->set_preset(view, phase);
    const cv::Mat picture = value_or_throw(renderer->render(*camera, style));
    ++rendered;
    if (video) {
      picture_writer.push([&writer, picture] { return writer.write(picture); });
    } else if (!o.output.empty()) {
      picture_writer.push(
          [path = frame_path(o.output, i, ".png"), picture] { return write_image(path, picture); });
    }
    if (std::find(sheet_positions.begin(), sheet_positions.end(), k) != sheet_positions.end()) {
      sheet_tiles.push_back(picture);
      sheet_labels.push_back("frame " + std::to_string(i));
    }
    per_frame.push_back(fj);
  }
  throw_if_error(picture_writer.finish());
  progress.finish();
  writer.release();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  if (!sheet_tiles.empty() && !o.contact_sheet.empty())
    throw_if_error(
        write_image(o.contact_sheet, contact_sheet(sheet_tiles, sheet_labels, o.contact_columns)));
  nlohmann::json stats = {{"input", o.input},
                          {"frames", per_frame},
                          {"summary",
                           {{"rendered", rendered},
                            {"failed", failures.size()},
                            {"failures", failures},
                            {"seconds", seconds},
                            {"frames_per_second", seconds > 0 ? rendered / seconds : 0.0},
                            {"renderer", renderer->description()},
                            {"video_codec", codec}}},
                          {"options",
                           {{"view", o.view},
                            {"size", o.size},
                            {"shading", o.shading},
                            {"frames", o.frames},
                            {"fps", fps},
                            {"reference", o.reference},
                            {"error_max_mm", error_max},
                            {"msaa", o.msaa},
                            {"mesh_stride", o.mesh_stride},
                            {"mesh_stride_used", mesh_options.stride},
                            {"contact_sheet", o.contact_sheet}}}};
  if (!o.output.empty()) {
    const fs::path stats_path = video ? fs::path(o.output).replace_extension(".stats.json")
                                      : fs::path(o.output) / "stats.json";
    throw_if_error(write_json(stats_path, stats));
  }
  std::printf("rendered %lld of %zu frames in %.2f s (%.1f frames/s)%s\n",
              static_cast<long long>(rendered), indices.size(), seconds,
              seconds > 0 ? rendered / seconds : 0.0, video ? (" as " + codec).c_str() : "");
  throw_if_error(failures_status(failures, indices.size()));
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "render", "Render a geometry video offscreen (no display needed) to MP4 or PNG frames");
  auto o = std::make_shared<RenderCommandOptions>();
  cmd->add_option("input", o->input, "Geometry video: FILE.gvid or a folder of frame_NNNNNN.exr")
      ->required();
  cmd->add_option("-o,--output", o->output, "OUT.mp4 (H.264 or MPEG-4) or a folder for PNG frames");
  cmd->add_option("--view", o->view, "front, left, right or orbit")->capture_default_str();
  cmd->add_option("--size", o->size, "Picture size WxH (px)")->capture_default_str();
  cmd->add_option("--shading", o->shading, "lit, texture, normals, wireframe or error")
      ->capture_default_str();
  cmd->add_option("--frames", o->frames, "Frames A:B (half-open), A:, :B or N")
      ->capture_default_str();
  cmd->add_option("--reference", o->reference, "Reference video for --shading error");
  cmd->add_option("--error-max", o->error_max_mm,
                  "Top of the error colour scale (mm); 0 = 99th percentile of the first frame");
  cmd->add_option("--fps", o->fps, "MP4 frame rate (default: the sequence's)");
  cmd->add_option("--msaa", o->msaa, "Multisample anti-aliasing samples (0..16)")
      ->capture_default_str();
  cmd->add_option("--mesh-stride", o->mesh_stride,
                  "Use every Nth pixel of the geometry image (1..16), or auto: about one grid "
                  "step per picture pixel (fewer triangles where they would be sub-pixel)")
      ->capture_default_str();
  cmd->add_option("--contact-sheet", o->contact_sheet, "Also write a PNG grid of frames here");
  cmd->add_option("--contact-frames", o->contact_frames, "Frames on the contact sheet")
      ->capture_default_str();
  cmd->add_option("--contact-columns", o->contact_columns, "Columns of the contact sheet")
      ->capture_default_str();
  cmd->callback([o] { run_render(*o); });
}

}  // namespace gvkit::tools
