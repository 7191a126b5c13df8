// gvkit record: frames from any source (v4l2:, libcamera:, file:) recorded losslessly and
// crash-safely into a folder (frame_NNNNNN.png + frames.json + stats.json), through the live
// pipeline with a status line.
#include <cstdio>
#include <memory>
#include <string>

#include "command.hpp"
#include "gvkit/capture/frame_recorder.hpp"
#include "gvkit/capture/frame_source.hpp"
#include "gvkit/capture/live_pipeline.hpp"
#include "gvkit/core/json_io.hpp"
#include "source_args.hpp"

namespace gvkit::tools {
namespace {

struct RecordArgs {
  std::string source, output, policy = "block";
  SourceArgs camera;
  int64_t frames = 0;
  double seconds = 0, fps = 0;
  int queue = 8, png_compression = 1;
  bool paced = false, quiet_status = false;
};

void run_record(const RecordArgs& a) {
  FrameSourceOptions so = value_or_throw(frame_source_options(a.camera));
  so.fps = a.fps;
  so.paced = a.paced;
  if (a.frames < 0) throw CommandFailed(invalid_argument("--frames must be >= 0"));
  if (a.queue < 1 || a.queue > 1024)
    throw CommandFailed(
        invalid_argument("--queue " + std::to_string(a.queue) + " is outside 1..1024"));
  const QueueFullPolicy policy = value_or_throw(parse_queue_full_policy(a.policy));
  LivePipelineOptions po;
  po.max_frames = a.frames;
  po.max_seconds = a.seconds;
  throw_if_error(po.check());
  throw_if_error(so.check());

  std::unique_ptr<FrameSource> source = value_or_throw(FrameSource::create(a.source, so));
  for (const std::string& r : source->refused_settings())
    std::fprintf(stderr, "warning: %s: %s\n", a.source.c_str(), r.c_str());
  const std::string description = source->describe();
  FrameRecorderOptions ro;
  ro.png_compression = a.png_compression;
  ro.source_description = description;
  std::shared_ptr<FrameRecorder> recorder(value_or_throw(FrameRecorder::create(a.output, ro)));

  LiveStage record;
  record.name = "record";
  record.queue_capacity = static_cast<size_t>(a.queue);
  record.when_full = policy;
  record.run = [recorder](std::any&& value) -> Result<std::optional<std::any>> {
    GVKIT_RETURN_IF_ERROR(recorder->append(std::any_cast<const CameraFrame&>(value)));
    return std::optional<std::any>(std::any());
  };
  po.status_interval_s = a.quiet_status ? 0 : 1;
  po.on_status = [](const LiveStatus& s) { std::fprintf(stderr, "%s\n", s.line().c_str()); };
  std::fprintf(stderr, "recording %s -> %s\n", description.c_str(), a.output.c_str());
  LivePipeline pipeline(std::move(source), {record}, po);
  throw_if_error(pipeline.start());
  const Status result = pipeline.wait();
  const LiveStatus status = pipeline.status();
  FrameSourceCounters counters = status.source;
  counters.dropped += status.stages[0].dropped;  // frames the recorder's queue had to let go
  recorder->set_source_counters(counters);
  const Status closed = recorder->close();

  nlohmann::json stats = {
      {"source", description},
      {"captured", status.captured},
      {"recorded", recorder->frames_written()},
      {"dropped_by_source", status.source.dropped},
      {"dropped_by_queue", status.stages[0].dropped},
      {"errored", status.source.errored},
      {"clamped_timestamps", status.source.clamped_timestamps},
      {"elapsed_s", status.elapsed_s},
      {"fps_in", status.elapsed_s > 0 ? status.captured / status.elapsed_s : 0.0},
      {"latency_mean_ms", status.stages[0].latency_mean_ms},
      {"latency_max_ms", status.stages[0].latency_max_ms},
      {"max_queue_depth", status.stages[0].max_queue_depth},
      {"stopped_by", result.is_ok() ? "" : result.message()},
      {"options",
       {{"source", a.source},
        {"frames", a.frames},
        {"seconds", a.seconds},
        {"fps", a.fps},
        {"exposure_us", a.camera.exposure_us},
        {"size", a.camera.size},
        {"pixel_format", a.camera.pixel_format},
        {"buffers", a.camera.buffers},
        {"queue", a.queue},
        {"policy", a.policy},
        {"paced", a.paced},
        {"png_compression", a.png_compression}}}};
  const Status stats_written = write_json(std::filesystem::path(a.output) / "stats.json", stats);
  std::fprintf(stderr, "recorded %lld frames into %s\n",
               static_cast<long long>(recorder->frames_written()), a.output.c_str());
  throw_if_error(result);
  throw_if_error(closed);
  throw_if_error(stats_written);
}

}  // namespace

void add_record_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "record", "Record frames from a camera or file source losslessly and crash-safely");
  auto a = std::make_shared<RecordArgs>();
  cmd->add_option("--source", a->source, "v4l2:/dev/videoN, libcamera:<id>, file:<path>")
      ->required();
  cmd->add_option("-o,--output", a->output, "Folder to create for the recording")->required();
  cmd->add_option("--frames", a->frames, "Stop after this many frames (0 = no limit)");
  cmd->add_option("--seconds", a->seconds, "Stop after this long (0 = no limit)");
  cmd->add_option("--fps", a->fps, "Frame rate to ask the camera for");
  add_source_flags(cmd, a->camera, "Frame size WxH to ask the camera for");
  cmd->add_option("--queue", a->queue, "Frames queued in front of the writer")
      ->capture_default_str();
  cmd->add_option("--policy", a->policy, "When the queue is full: block, drop-oldest, drop-newest")
      ->capture_default_str();
  cmd->add_option("--png-compression", a->png_compression, "zlib level 0..9 (lossless)")
      ->capture_default_str();
  cmd->add_flag("--paced", a->paced, "Replay file sources in real time at --fps");
  cmd->add_flag("--no-status", a->quiet_status, "No status line every second");
  cmd->callback([a] { run_record(*a); });
}

}  // namespace gvkit::tools
