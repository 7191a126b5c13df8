// gvkit capture: a structured-light capture session, live. Frames from a source (synthetic rig,
// camera, replayed session) are paired with the projected patterns, recorded crash-safely into a
// session folder (SessionWriter), and optionally reconstructed and previewed as they come:
//   capture thread -> sync (frames -> fringe sets) -> record -> [reconstruct (+ preview)]
// on bounded queues, with a status line every second and stats.json at the end. The record
// stage hands each set to two bounded writer threads (RecordWriters) and passes it on at once;
// its latency is arrival -> queued for writing, stats.json record_writes has arrival -> written.
// `gvkit record` keeps the raw-frame recorder (no patterns); both share the camera flags.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gvkit/capture/expression_track.hpp"
#include "gvkit/capture/frame_source.hpp"
#include "gvkit/capture/ground_truth.hpp"
#include "gvkit/capture/live_pipeline.hpp"
#include "gvkit/capture/pattern_projector.hpp"
#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/pattern_sync.hpp"
#include "gvkit/capture/projector_gamma.hpp"
#include "gvkit/capture/reconstructor.hpp"
#include "gvkit/capture/scan_accuracy.hpp"
#include "gvkit/capture/session_reader.hpp"
#include "gvkit/capture/session_writer.hpp"
#include "gvkit/capture/synthetic_stream.hpp"
#include "gvkit/core/calibration_io.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/face_landmarks_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/player/live_frame_queue.hpp"
#include "source_args.hpp"
#include "tool_support.hpp"
#ifdef GVKIT_WITH_PLAYER
#include "gvkit/player/player_window.hpp"
#endif

namespace gvkit::tools {
namespace {
namespace fs = std::filesystem;

// The synthetic rig's projector: a DLP-class projector showing up to this many patterns per
// second (the rate check of --fps against the pattern count).
constexpr double kSyntheticProjectorHz = 120;

// Ctrl-C stops the capture cleanly (LivePipeline::stop only sets an atomic flag).
std::atomic<LivePipeline*> g_running_pipeline{nullptr};
void stop_on_signal(int) {
  if (LivePipeline* p = g_running_pipeline.load()) p->stop();
}

struct CaptureArgs {
  std::string source, pattern, output, calibration, sync = "auto", policy = "block", scans;
  SourceArgs camera;
  int project = -1;
  int64_t frames = 0;
  double seconds = 0, fps = 0, projector_rate = 0, display_latency_ms = 0, gamma_compensate = 0;
  double depth_prior = 0;  // 0: the replayed session's, else the synthetic face's, else 650 mm
  int queue = 8, preview_stride = 2;
  bool reconstruct = false, preview = false, preview_optional = false, quiet_status = false;
  // synthetic:
  std::string ict, expressions = "mix";
  uint64_t seed = 1;
  double noise = 0;
  int bit_depth = 8;
  bool no_ground_truth = false, cue = false;
};

std::filesystem::path default_ict_dir() {
  if (const char* env = std::getenv("GVKIT_SHARED_DATA"))
    return std::filesystem::path(env) / "ict-facekit";
  return GVKIT_DEFAULT_SHARED_DATA "/ict-facekit";
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", v);
  return text;
}

bool have_display() {
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  return (display && *display) || (wayland && *wayland);
}

struct FrameAccuracy {
  int64_t index = 0;
  double valid_share = 0;
  std::optional<capture::ScanAccuracy> accuracy;
};

// What the record stage hands to the writers: the set and what goes beside it into gt/.
struct RecordJob {
  FringeSet set;
  std::optional<capture::GroundTruth> truth;  // synthetic: written as gt/frame_N.exr
  FaceLandmarks landmarks;                    // synthetic: gt/frame_N.landmarks.json
  bool copy_replayed_truth = false;           // replay: gt/ files copied from the session
};

// The writes of the record stage on their own threads: the stage queues a set here and passes
// it on at once, so reconstruction does not wait for the PNG encoding and the fsyncs, and two
// sets are written at a time (their fsync waits overlap). Bounded: when `capacity` sets wait,
// the record stage blocks and the queue in front of it applies the --policy. SessionWriter
// lists a set only after its images are on disk, in index order whatever order they finish in.
struct RecordWriters {
  static constexpr int kThreads = 2;
  explicit RecordWriters(size_t capacity) : queue(capacity, QueueFullPolicy::kBlock) {}
  ~RecordWriters() {  // also on an exception before finish_record_writers
    queue.close();
    for (std::thread& t : threads)
      if (t.joinable()) t.join();
  }
  BoundedQueue<RecordJob> queue;
  std::vector<std::thread> threads;
  std::mutex mutex;  // guards the figures below and failure
  Status failure;
  int64_t written = 0;
  double write_ms_sum = 0, write_ms_max = 0;  // queued -> written (images, gt, session.json)

  Status first_failure() {
    std::lock_guard<std::mutex> lock(mutex);
    return failure;
  }
};

// Everything the stages share.
struct CaptureRun {
  CaptureArgs args;
  std::shared_ptr<capture::SyntheticStream> synthetic;
  std::optional<capture::SessionReader> replayed;  // file:SESSION
  Calibration calibration;
  std::unique_ptr<capture::PatternSet> patterns;
  std::optional<capture::Reconstructor> reconstructor;
  // Recorded in session.json, used by the live reconstruction.
  double depth_prior_mm = capture::ReconstructOptions{}.depth_prior_mm;
  std::string sync_mode;  // tagged | cue | software
  int frames_per_cycle = 0;
  std::string description;

  // sync stage
  std::optional<TaggedPatternSync> tagged;
  std::optional<HardwareTriggeredSync> cue;
  std::unique_ptr<SoftwareSyncStream> software;
  std::mutex sync_mutex;  // guards the sync counters read by the status thread

  // record stage
  std::unique_ptr<capture::SessionWriter> writer;
  std::unique_ptr<RecordWriters> writers;
  bool write_ground_truth = false;
  std::atomic<int64_t> recorded{0};
  // Cycles the sync had dropped when --frames was reached (later drops concern frames that were
  // in flight after the stop and are not part of the session).
  std::optional<int64_t> cycles_dropped_at_limit;
  int64_t ground_truth_missing = 0;

  // reconstruct stage
  std::mutex accuracy_mutex;
  std::vector<FrameAccuracy> accuracy;
  std::shared_ptr<player::LiveFrameQueue> preview;

  LivePipeline* pipeline = nullptr;

  SyncCounters sync_counters() {
    std::lock_guard<std::mutex> lock(sync_mutex);
    if (tagged) return tagged->counters();
    if (cue) return cue->counters();
    if (software) return software->counters();
    return {};
  }
};

Result<std::optional<std::any>> sync_stage(CaptureRun& run, std::any&& value) {
  const CameraFrame& frame = std::any_cast<const CameraFrame&>(value);
  std::optional<FrameGroup> group;
  {
    std::lock_guard<std::mutex> lock(run.sync_mutex);
    if (run.tagged)
      group = run.tagged->push(frame);
    else if (run.cue)
      group = run.cue->push(frame);
    else
      group = run.software->push(frame);
  }
  if (!group) return std::optional<std::any>();
  // Synthetic and replayed frames number their cycles by sequence; the index of a set is the
  // instant it shows (so ground truth stays matched across dropped cycles).
  if (run.sync_mode == "cue" && run.synthetic)
    group->index = group->sequences.front() / run.frames_per_cycle;
  return std::optional<std::any>(to_fringe_set(std::move(*group)));
}

Status copy_replayed_ground_truth(const CaptureRun& run, int64_t index) {
  const fs::path from = run.replayed->dir() / run.replayed->info().ground_truth_dir;
  const fs::path to = run.writer->dir() / "gt";
  for (const char* ext : {".exr", ".landmarks.json"}) {
    const fs::path src = frame_path(from, index, ext);
    std::error_code ec;
    if (!fs::exists(src, ec)) continue;
    fs::copy_file(src, frame_path(to, index, ext), fs::copy_options::overwrite_existing, ec);
    if (ec) return io_error(src.string() + ": cannot copy into the session: " + ec.message());
  }
  return Status::ok();
}

Status open_session(CaptureRun& run, const FringeSet& first) {
  capture::SessionInfo info;
  info.pattern = run.patterns->name();
  info.images_per_frame = run.patterns->image_count();
  info.width = first.size().width;
  info.height = first.size().height;
  const bool wide = first.images.front().depth() == CV_16U;
  info.bit_depth = wide ? 16 : 8;
  info.fps = run.args.fps > 0 ? run.args.fps : 30;
  const bool ground_truth =
      !run.args.no_ground_truth &&
      (run.synthetic || (run.replayed && !run.replayed->info().ground_truth_dir.empty()));
  if (ground_truth) info.ground_truth_dir = "gt";
  info.depth_prior_mm = run.depth_prior_mm;
  run.write_ground_truth = ground_truth;
  if (run.synthetic) {
    info.bit_depth = run.synthetic->options().render.bit_depth;
    info.source = run.synthetic->options().to_json();
  } else if (run.replayed) {
    info.bit_depth = run.replayed->info().bit_depth;
    info.fps = run.args.fps > 0 ? run.args.fps : run.replayed->info().fps;
    info.source = {{"kind", "replay"},
                   {"session", run.replayed->dir().string()},
                   {"recorded_source", run.replayed->info().source}};
  } else {
    info.source = {{"kind", "camera"}, {"uri", run.args.source}, {"device", run.description}};
  }
  info.source["sync"] = run.sync_mode;
  GVKIT_ASSIGN_OR_RETURN(run.writer,
                         capture::SessionWriter::create(run.args.output, info, run.calibration));
  return Status::ok();
}

Status write_record_job(const CaptureRun& run, const RecordJob& job) {
  GVKIT_RETURN_IF_ERROR(run.writer->append(job.set));
  const fs::path gt = run.writer->dir() / "gt";
  if (job.truth) {
    GVKIT_RETURN_IF_ERROR(
        capture::write_ground_truth_exr(frame_path(gt, job.set.index, ".exr"), *job.truth));
    GVKIT_RETURN_IF_ERROR(
        write_face_landmarks(frame_path(gt, job.set.index, ".landmarks.json"), job.landmarks));
  }
  if (job.copy_replayed_truth)
    GVKIT_RETURN_IF_ERROR(copy_replayed_ground_truth(run, job.set.index));
  return Status::ok();
}

void start_record_writers(CaptureRun& run) {
  run.writers = std::make_unique<RecordWriters>(static_cast<size_t>(run.args.queue));
  for (int t = 0; t < RecordWriters::kThreads; ++t)
    run.writers->threads.emplace_back([&run] {
      RecordWriters& w = *run.writers;
      while (std::optional<RecordJob> job = w.queue.pop()) {
        const auto start = std::chrono::steady_clock::now();
        Status s = write_record_job(run, *job);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        std::lock_guard<std::mutex> lock(w.mutex);
        if (!s.is_ok()) {
          if (w.failure.is_ok()) w.failure = s;
          if (run.pipeline) run.pipeline->stop();
          continue;  // drain: later sets are not written once one failed
        }
        if (!w.failure.is_ok()) continue;
        ++w.written;
        w.write_ms_sum += ms;
        w.write_ms_max = std::max(w.write_ms_max, ms);
      }
    });
}

// Waits until every queued set is written; the first write failure.
Status finish_record_writers(CaptureRun& run) {
  if (!run.writers) return Status::ok();
  run.writers->queue.close();
  for (std::thread& t : run.writers->threads)
    if (t.joinable()) t.join();
  const Status failure = run.writers->first_failure();
  return failure.is_ok() ? failure : failure.with_context("record");
}

Result<std::optional<std::any>> record_stage(CaptureRun& run, std::any&& value) {
  FringeSet& set = std::any_cast<FringeSet&>(value);
  if (run.args.frames > 0 && run.recorded >= run.args.frames)
    return std::optional<std::any>();  // sets that were on their way when the count was reached
  if (!run.writer) GVKIT_RETURN_IF_ERROR(open_session(run, set));
  GVKIT_RETURN_IF_ERROR(run.writers->first_failure());
  RecordJob job;
  job.set = set;  // shares the pixels with the set passed on (both only read them)
  if (run.write_ground_truth) {
    if (run.synthetic) {
      // Looked up now: the stream keeps the truth of recent instants only.
      if (std::optional<capture::GroundTruth> truth = run.synthetic->truth(set.index)) {
        job.truth = std::move(truth);
        job.landmarks = run.synthetic->landmarks(set.index);
      } else {
        ++run.ground_truth_missing;
      }
    } else if (run.replayed) {
      job.copy_replayed_truth = true;
    }
  }
  if (!run.writers->queue.push(std::move(job))) return io_error("record: the writers stopped");
  if (++run.recorded == run.args.frames && run.pipeline) {
    run.cycles_dropped_at_limit = run.sync_counters().cycles_dropped;
    run.pipeline->stop();
  }
  if (!run.reconstructor) return std::optional<std::any>(std::any());
  return std::optional<std::any>(std::move(value));
}

Result<std::optional<std::any>> reconstruct_stage(CaptureRun& run, std::any&& value) {
  const FringeSet& set = std::any_cast<const FringeSet&>(value);
  GVKIT_ASSIGN_OR_RETURN(RangeScan scan, run.reconstructor->reconstruct(set, *run.patterns));
  FrameAccuracy a;
  a.index = set.index;
  a.valid_share = scan.valid_fraction();
  std::optional<capture::GroundTruth> truth;
  if (run.synthetic) {
    truth = run.synthetic->truth(set.index);
  } else if (run.replayed && !run.args.no_ground_truth) {
    if (auto path = run.replayed->ground_truth_path(set.index)) {
      GVKIT_ASSIGN_OR_RETURN(capture::GroundTruth gt, capture::read_ground_truth_exr(*path));
      truth = std::move(gt);
    }
  }
  if (truth && truth->xyz_mm.size() == scan.size())
    a.accuracy = capture::scan_accuracy(scan, *truth);
  if (!run.args.scans.empty())
    GVKIT_RETURN_IF_ERROR(
        write_range_scan_exr(frame_path(run.args.scans, set.index, ".exr"), scan));
  if (run.preview) GVKIT_RETURN_IF_ERROR(run.preview->push(scan));
  {
    std::lock_guard<std::mutex> lock(run.accuracy_mutex);
    run.accuracy.push_back(a);
  }
  return std::optional<std::any>(std::any());
}

nlohmann::json stage_json(const LiveStageStatus& s, double elapsed_s) {
  return {{"in", s.in},
          {"out", s.out},
          {"out_per_s", elapsed_s > 0 ? s.out / elapsed_s : 0.0},
          {"dropped", s.dropped},
          {"max_queue_depth", s.max_queue_depth},
          {"queue_capacity", s.queue_capacity},
          {"latency_mean_ms", s.latency_mean_ms},
          {"latency_max_ms", s.latency_max_ms}};
}

// Projects the patterns on the chosen monitor, cycle after cycle, until the pipeline ends.
#ifdef GVKIT_WITH_PROJECTOR
Status run_projector(CaptureRun& run, PatternProjector& projector, const std::atomic<bool>& done) {
  const int n = run.patterns->image_count();
  const double pattern_s = run.args.fps > 0 ? 1.0 / (run.args.fps * n) : 0.0;
  auto next = std::chrono::steady_clock::now();
  for (int64_t cycle = 0; !done && !projector.close_requested(); ++cycle) {
    for (int k = 0; k < n && !done; ++k) {
      GVKIT_ASSIGN_OR_RETURN(Timestamp shown, projector.show(k));
      run.software->presented({cycle, k, shown});
      next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(pattern_s));
      std::this_thread::sleep_until(next);
    }
  }
  if (projector.close_requested()) run.pipeline->stop();
  return Status::ok();
}
#endif

void run_capture(const CaptureArgs& a) {
  auto run = std::make_shared<CaptureRun>();
  run->args = a;
  CaptureArgs& args = run->args;
  // ---- options ----
  if (args.frames < 0) throw CommandFailed(invalid_argument("--frames must be >= 0"));
  if (!(args.seconds >= 0)) throw CommandFailed(invalid_argument("--seconds must be >= 0"));
  if (!(args.fps >= 0 && args.fps <= 1000))
    throw CommandFailed(invalid_argument("--fps " + number(args.fps) +
                                         " is outside 0..1000 (fringe sets per second)"));
  if (args.queue < 1 || args.queue > 1024)
    throw CommandFailed(
        invalid_argument("--queue " + std::to_string(args.queue) + " is outside 1..1024"));
  if (!(args.gamma_compensate == 0 || (args.gamma_compensate >= 0.2 && args.gamma_compensate <= 5)))
    throw CommandFailed(invalid_argument("--gamma-compensate must be 0 (off) or in [0.2, 5]"));
  if (!(args.display_latency_ms >= 0 && args.display_latency_ms <= 1000))
    throw CommandFailed(invalid_argument("--display-latency-ms must be in 0..1000"));
  if (args.preview_stride < 1 || args.preview_stride > 16)
    throw CommandFailed(invalid_argument("--preview-stride must be 1..16"));
  const QueueFullPolicy policy = value_or_throw(parse_queue_full_policy(args.policy));
  if (args.sync != "auto" && args.sync != "tagged" && args.sync != "cue" && args.sync != "software")
    throw CommandFailed(
        invalid_argument("--sync '" + args.sync + "' is not one of auto, tagged, cue, software"));
  if (!args.scans.empty()) args.reconstruct = true;
  if (args.preview) args.reconstruct = true;
  if (args.preview && args.project >= 0)
    throw CommandFailed(invalid_argument(
        "--preview and --project both need the one GLFW window of the process; leave one out"));
  if (args.preview) {
#ifndef GVKIT_WITH_PLAYER
    if (!args.preview_optional)
      throw CommandFailed(unsupported("--preview: this build has no player (GVKIT_WITH_PLAYER)"));
    std::fprintf(stderr, "warning: no player in this build; capturing without the preview\n");
    args.preview = false;
#else
    if (!have_display()) {
      if (!args.preview_optional)
        throw CommandFailed(failed_precondition(
            "--preview needs a display, but DISPLAY and WAYLAND_DISPLAY are unset; run without "
            "--preview, or add --preview-optional to capture without the window when there is "
            "no display"));
      std::fprintf(stderr,
                   "warning: no display (DISPLAY and WAYLAND_DISPLAY are unset): capturing "
                   "without the preview (--preview-optional)\n");
      args.preview = false;
    }
#endif
  }

  const size_t colon = args.source.find(':');
  const std::string scheme = colon == std::string::npos ? "" : args.source.substr(0, colon);
  const std::string rest = colon == std::string::npos ? "" : args.source.substr(colon + 1);
  std::error_code ec;
  if (scheme == "file" && fs::exists(fs::path(rest) / "session.json", ec))
    run->replayed = value_or_throw(capture::SessionReader::open(rest));
  if (args.pattern.empty()) {
    if (!run->replayed)
      throw CommandFailed(
          invalid_argument("--pattern is required (" + capture::pattern_set_help() + ")"));
    args.pattern = run->replayed->info().pattern;
  }
  run->patterns = value_or_throw(capture::create_pattern_set(args.pattern));
  const int n = run->patterns->image_count();
  if (run->replayed && run->replayed->info().images_per_frame != n)
    throw CommandFailed(invalid_argument(
        "--pattern " + args.pattern + " has " + std::to_string(n) + " images, but the session " +
        rest + " was recorded with " + run->replayed->info().pattern + " (" +
        std::to_string(run->replayed->info().images_per_frame) + " images)"));

  // ---- sync mode and projector rate ----
  run->sync_mode = args.sync;
  if (run->sync_mode == "auto")
    run->sync_mode = args.project >= 0                      ? "software"
                     : (scheme == "synthetic" && !args.cue) ? "tagged"
                     : run->replayed                        ? "tagged"
                                                            : "cue";
  if (run->sync_mode == "software" && args.project < 0)
    throw CommandFailed(invalid_argument(
        "--sync software needs --project MONITOR (gvkit shows the patterns itself)"));
  if (run->sync_mode == "tagged" && scheme != "synthetic" && !run->replayed)
    throw CommandFailed(invalid_argument(
        "--sync tagged needs a source that knows its patterns (synthetic: or a session folder)"));
  if (scheme == "synthetic" && args.project >= 0)
    throw CommandFailed(invalid_argument(
        "--project with the synthetic source: the synthetic rig renders its own projector"));
  if (run->replayed && run->sync_mode != "tagged")
    throw CommandFailed(
        invalid_argument("a replayed session carries its pattern tags: use --sync tagged"));
  const bool cue_frame = run->sync_mode == "cue";
  run->frames_per_cycle = n + (cue_frame ? 1 : 0);
  double projector_hz = args.projector_rate;
  if (projector_hz <= 0 && scheme == "synthetic") projector_hz = kSyntheticProjectorHz;

  // ---- calibration and the source ----
  FrameSourceOptions so = value_or_throw(frame_source_options(args.camera));
  so.fps = args.fps * run->frames_per_cycle;  // the camera sees every pattern (and the cue)
  if (scheme == "synthetic") {
    capture::SyntheticStreamOptions o;
    o.ict_dir = args.ict.empty() ? default_ict_dir() : fs::path(args.ict);
    o.pattern = args.pattern;
    o.expressions = args.expressions;
    o.seed = args.seed;
    o.pose_fps = args.fps > 0 ? args.fps : 30;
    o.cue = cue_frame;
    o.render.noise_sigma = args.noise;
    o.render.bit_depth = args.bit_depth;
    if (so.width > 0) {
      o.rig.camera_width = so.width;
      o.rig.camera_height = so.height;
    }
    o.keep_truth = std::max(16, 2 * args.queue + 8);
    run->synthetic = value_or_throw(capture::SyntheticStream::create(o));
    run->calibration = run->synthetic->calibration();
    so.synthetic_generator = run->synthetic->generator();
    so.pattern_cycle = run->frames_per_cycle;
    so.cue_frames = cue_frame ? 1 : 0;
    so.paced = args.fps > 0;
    so.drop_late = so.paced;  // a camera does not wait: late frames are dropped and counted
    if (!so.paced && args.frames > 0 && run->sync_mode == "tagged")
      so.frame_count = args.frames * run->frames_per_cycle;
    so.width = so.height = 0;
  } else if (run->replayed) {
    run->calibration = run->replayed->calibration();
  }
  if (scheme == "file") so.paced = args.fps > 0;  // a replay stands in for a camera at --fps
  if (args.fps > 0)
    throw_if_error(
        check_pattern_rate(run->frames_per_cycle, args.fps, projector_hz)
            .with_context("--pattern " + args.pattern + " at --fps " + number(args.fps)));
  std::unique_ptr<FrameSource> source = value_or_throw(FrameSource::create(args.source, so));
  if (!args.calibration.empty())
    run->calibration = value_or_throw(read_calibration(args.calibration)).calibration;
  else if (!run->synthetic && !run->replayed)
    throw CommandFailed(invalid_argument(
        "--calibration FILE is required for a camera source (gvkit calibrate makes one)"));
  if (run->calibration.fringe_pitch_px <= 0)
    run->calibration.fringe_pitch_px = run->patterns->pitch_px(run->calibration.projector_width);
  if (!(args.depth_prior >= 0))
    throw CommandFailed(invalid_argument("--depth-prior must be a depth in mm"));
  if (args.depth_prior > 0)
    run->depth_prior_mm = args.depth_prior;
  else if (run->replayed && run->replayed->info().depth_prior_mm > 0)
    run->depth_prior_mm = run->replayed->info().depth_prior_mm;
  else if (run->synthetic)
    run->depth_prior_mm = run->synthetic->options().face_distance_mm;
  if (args.reconstruct) {
    capture::ReconstructOptions reconstruct_options;
    reconstruct_options.depth_prior_mm = run->depth_prior_mm;
    run->reconstructor =
        value_or_throw(capture::Reconstructor::create(run->calibration, reconstruct_options));
  }
  std::error_code exists_ec;
  if (fs::exists(fs::path(args.output) / "session.json", exists_ec))
    throw CommandFailed(invalid_argument(args.output + ": already holds a session (session.json)"));

#ifdef GVKIT_WITH_PROJECTOR
  std::unique_ptr<PatternProjector> projector;
#endif
  if (args.project >= 0) {
#ifdef GVKIT_WITH_PROJECTOR
    PatternProjectorOptions po;
    po.monitor = args.project;
    projector = value_or_throw(PatternProjector::open(po));
    if (args.projector_rate <= 0) projector_hz = projector->refresh_hz();
    if (args.fps > 0)
      throw_if_error(
          check_pattern_rate(n, args.fps, projector_hz)
              .with_context("--pattern " + args.pattern + " on " + projector->describe()));
    std::vector<cv::Mat> images = run->patterns->generate(projector->size());
    if (args.gamma_compensate > 0) capture::compensate_gamma(images, args.gamma_compensate);
    for (cv::Mat& image : images) image.convertTo(image, CV_8U, 255.0);
    throw_if_error(projector->set_patterns(images));
#else
    throw CommandFailed(
        unsupported("--project: this build has no projector window "
                    "(GVKIT_WITH_PROJECTOR)"));
#endif
  }

  for (const std::string& r : source->refused_settings())
    std::fprintf(stderr, "warning: %s: %s\n", args.source.c_str(), r.c_str());
  run->description = source->describe();
  if (run->sync_mode == "tagged")
    run->tagged.emplace(TaggedSyncOptions{n, run->frames_per_cycle});
  else if (run->sync_mode == "cue")
    run->cue.emplace(HardwareSyncOptions::cue(n));
  else {
    SoftwareSyncOptions o;
    o.patterns_per_cycle = n;
    o.display_latency = Timestamp(static_cast<int64_t>(args.display_latency_ms * 1e6));
    run->software = std::make_unique<SoftwareSyncStream>(o);
  }
  if (!args.scans.empty()) throw_if_error(ensure_directory(args.scans));

  // ---- the pipeline ----
  std::vector<LiveStage> stages;
  LiveStage sync{"sync", [run](std::any&& v) { return sync_stage(*run, std::move(v)); },
                 static_cast<size_t>(std::max(args.queue, 2 * run->frames_per_cycle)), policy};
  LiveStage record{"record", [run](std::any&& v) { return record_stage(*run, std::move(v)); },
                   static_cast<size_t>(args.queue), policy};
  stages.push_back(sync);
  stages.push_back(record);
  if (args.reconstruct)
    stages.push_back({"reconstruct",
                      [run](std::any&& v) { return reconstruct_stage(*run, std::move(v)); },
                      static_cast<size_t>(args.queue), policy});
  if (args.preview) run->preview = std::make_shared<player::LiveFrameQueue>(2);

  LivePipelineOptions po;
  po.max_seconds = args.seconds;
  po.status_interval_s = args.quiet_status ? 0 : 1;
  po.on_status = [run](const LiveStatus& s) {
    const SyncCounters c = run->sync_counters();
    std::fprintf(stderr, "%s | sets %lld, cycles dropped %lld\n", s.line().c_str(),
                 static_cast<long long>(run->recorded.load()),
                 static_cast<long long>(c.cycles_dropped));
  };
  std::fprintf(stderr, "capturing %s, %s (%s sync, %d frames per set) -> %s\n",
               run->description.c_str(), run->patterns->name().c_str(), run->sync_mode.c_str(),
               run->frames_per_cycle, args.output.c_str());
  start_record_writers(*run);
  LivePipeline pipeline(std::move(source), stages, po);
  run->pipeline = &pipeline;
  throw_if_error(pipeline.start());
  g_running_pipeline = &pipeline;
  auto previous_handler = std::signal(SIGINT, stop_on_signal);

  Status preview_status;
#ifdef GVKIT_WITH_PROJECTOR
  std::atomic<bool> pipeline_done{false};
  std::thread waiter;
  Status projector_status;
  if (projector) {
    waiter = std::thread([&] {
      (void)pipeline.wait();
      pipeline_done = true;
    });
    projector_status = run_projector(*run, *projector, pipeline_done);
    if (!projector_status.is_ok()) pipeline.stop();
    waiter.join();
    projector.reset();
  }
#endif
#ifdef GVKIT_WITH_PLAYER
  if (args.preview) {
    std::thread closer([&] {
      (void)pipeline.wait();
      run->preview->close();
    });
    player::PlayerWindowOptions wo;
    wo.live = run->preview;
    wo.close_when_live_ends = true;
    wo.mesh.stride = args.preview_stride;
    wo.mesh.max_edge_mm = 10;
    wo.title = "gvkit capture";
    wo.live_status = [&pipeline, run] {
      const SyncCounters c = run->sync_counters();
      return pipeline.status().line() + "\nsets " + std::to_string(run->recorded.load()) +
             ", cycles dropped " + std::to_string(c.cycles_dropped);
    };
    preview_status = player::run_player_window(wo);
    if (!preview_status.is_ok()) {
      if (args.preview_optional) {
        std::fprintf(stderr, "warning: preview: %s; capturing without it\n",
                     preview_status.message().c_str());
        preview_status = Status::ok();
      } else {
        pipeline.stop();
      }
    } else {
      pipeline.stop();  // the window was closed: stop capturing (no-op when it ended already)
    }
    closer.join();
  }
#endif
  const Status result = pipeline.wait();
  const Status written = finish_record_writers(*run);
  std::signal(SIGINT, previous_handler);
  g_running_pipeline = nullptr;
  // A cycle still incomplete when capture stopped was cut by the stop, not lost: it is counted
  // apart from the cycles the sync dropped.
  const int64_t cycles_dropped =
      run->cycles_dropped_at_limit.value_or(run->sync_counters().cycles_dropped);
  {
    std::lock_guard<std::mutex> lock(run->sync_mutex);
    if (run->tagged) run->tagged->finish();
    if (run->cue) run->cue->finish();
  }
  const LiveStatus status = pipeline.status();
  const SyncCounters sync_counters = run->sync_counters();
  Status closed;
  if (run->writer) {
    const int64_t dropped_sets = cycles_dropped + status.stages[1].dropped;
    if (dropped_sets > 0) closed = run->writer->add_dropped(dropped_sets);
  }

  // ---- stats.json ----
  std::sort(run->accuracy.begin(), run->accuracy.end(),
            [](const FrameAccuracy& x, const FrameAccuracy& y) { return x.index < y.index; });
  nlohmann::json frames = nlohmann::json::array();
  double valid_sum = 0, rms2 = 0, interior2 = 0, interior_share = 0;
  int with_truth = 0;
  for (const FrameAccuracy& f : run->accuracy) {
    nlohmann::json j = {{"index", f.index}, {"valid_share", f.valid_share}};
    valid_sum += f.valid_share;
    if (f.accuracy) {
      j["rms_depth_error_mm"] = f.accuracy->rms_mm;
      j["p99_depth_error_mm"] = f.accuracy->p99_mm;
      j["face_interior_rms_mm"] = f.accuracy->face_interior_rms_mm;
      j["face_interior_valid_share"] = f.accuracy->face_interior_valid_share;
      rms2 += f.accuracy->rms_mm * f.accuracy->rms_mm;
      interior2 += f.accuracy->face_interior_rms_mm * f.accuracy->face_interior_rms_mm;
      interior_share += f.accuracy->face_interior_valid_share;
      ++with_truth;
    }
    frames.push_back(j);
  }
  const double elapsed = status.elapsed_s;
  nlohmann::json summary = {
      {"source", run->description},
      {"sync", run->sync_mode},
      {"frames_per_set", run->frames_per_cycle},
      {"camera_frames", status.captured},
      {"camera_fps", elapsed > 0 ? status.captured / elapsed : 0.0},
      {"sets_recorded", run->recorded.load()},
      {"sets_per_s", elapsed > 0 ? run->recorded.load() / elapsed : 0.0},
      {"elapsed_s", elapsed},
      {"dropped_by_source", status.source.dropped},
      {"errored_by_source", status.source.errored},
      {"cycles_dropped_by_sync", cycles_dropped},
      {"cycles_cut_by_the_stop", sync_counters.cycles_dropped - cycles_dropped},
      {"frames_unused_by_sync", sync_counters.frames_unused},
      {"ground_truth_missing", run->ground_truth_missing},
      {"stopped_by", result.is_ok() ? "" : result.message()}};
  nlohmann::json stage_stats = nlohmann::json::object();
  for (const LiveStageStatus& s : status.stages) stage_stats[s.name] = stage_json(s, elapsed);
  summary["stages"] = stage_stats;
  {
    RecordWriters& w = *run->writers;
    const double mean = w.written > 0 ? w.write_ms_sum / static_cast<double>(w.written) : 0.0;
    // Arrival -> set on disk: the record stage's latency (arrival -> queued for writing) plus
    // the write (queued -> written), as means.
    summary["record_writes"] = {
        {"sets_written", w.written},
        {"write_ms_mean", mean},
        {"write_ms_max", w.write_ms_max},
        {"latency_written_mean_ms", status.stages[1].latency_mean_ms + mean},
        {"threads", RecordWriters::kThreads}};
  }
  if (run->synthetic) summary["synthetic_render_ms_mean"] = run->synthetic->mean_render_ms();
  if (!run->accuracy.empty()) {
    summary["reconstructed"] = run->accuracy.size();
    summary["mean_valid_share"] = valid_sum / static_cast<double>(run->accuracy.size());
  }
  if (with_truth) {
    summary["rms_depth_error_mm"] = std::sqrt(rms2 / with_truth);
    summary["face_interior_rms_mm"] = std::sqrt(interior2 / with_truth);
    summary["face_interior_valid_share"] = interior_share / with_truth;
  }
  if (run->preview) {
    summary["preview_pushed"] = run->preview->pushed();
    summary["preview_dropped"] = run->preview->dropped();
  }
  nlohmann::json options = {{"source", args.source},
                            {"pattern", run->patterns->name()},
                            {"project", args.project},
                            {"sync", args.sync},
                            {"frames", args.frames},
                            {"seconds", args.seconds},
                            {"fps", args.fps},
                            {"projector_rate_hz", projector_hz},
                            {"gamma_compensate", args.gamma_compensate},
                            {"display_latency_ms", args.display_latency_ms},
                            {"queue", args.queue},
                            {"policy", args.policy},
                            {"reconstruct", args.reconstruct},
                            {"scans", args.scans},
                            {"preview", args.preview},
                            {"size", args.camera.size},
                            {"noise", args.noise},
                            {"seed", args.seed},
                            {"expressions", args.expressions}};
  Status stats_written;
  if (run->writer)
    stats_written = write_json(
        fs::path(args.output) / "stats.json",
        {{"command", "capture"}, {"options", options}, {"summary", summary}, {"frames", frames}});
  std::fprintf(stderr, "captured %lld sets (%lld camera frames, %.1f s) into %s",
               static_cast<long long>(run->recorded.load()),
               static_cast<long long>(status.captured), elapsed, args.output.c_str());
  if (with_truth)
    std::fprintf(stderr, "; live RMS depth error %.4f mm (face interior %.4f mm)",
                 summary["rms_depth_error_mm"].get<double>(),
                 summary["face_interior_rms_mm"].get<double>());
  std::fprintf(stderr, "\n");
#ifdef GVKIT_WITH_PROJECTOR
  throw_if_error(projector_status);
#endif
  throw_if_error(result);
  throw_if_error(written);
  throw_if_error(preview_status);
  throw_if_error(closed);
  throw_if_error(stats_written);
  if (!run->writer)
    throw CommandFailed(not_found(args.source + ": no complete pattern cycle arrived; nothing "
                                                "was recorded"));
}

}  // namespace

void add_capture_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "capture",
      "Capture a structured-light session: frames paired with patterns, recorded crash-safely "
      "into a session folder, optionally reconstructed and previewed live");
  auto a = std::make_shared<CaptureArgs>();
  cmd->add_option("--source", a->source,
                  "synthetic: (the synthetic projector-camera rig), v4l2:/dev/videoN, "
                  "libcamera:<id>, file:<session folder>")
      ->required();
  cmd->add_option(
      "--pattern", a->pattern,
      "Pattern set (default for file:SESSION: the session's): " + capture::pattern_set_help());
  cmd->add_option("-o,--output", a->output, "Session folder to create")->required();
  cmd->add_option("--project", a->project,
                  "Show the patterns fullscreen on this monitor (0 = primary) and pair frames "
                  "by software sync");
  auto* frames = cmd->add_option("--frames", a->frames, "Stop after this many fringe sets");
  cmd->add_option("--seconds", a->seconds, "Stop after this long")->excludes(frames);
  cmd->add_option("--fps", a->fps,
                  "Fringe sets per second (the camera runs at this times the frames per set); "
                  "0 = as fast as possible (synthetic) or the camera's rate");
  cmd->add_option("--sync", a->sync,
                  "auto, tagged (the source knows each frame's pattern: synthetic, session "
                  "replay), cue (a projector sequencing the patterns itself after a white cue "
                  "frame), software (with --project)")
      ->capture_default_str();
  cmd->add_option("--projector-rate", a->projector_rate,
                  "Patterns per second the projector can show (default: the monitor's refresh "
                  "with --project, 120 for synthetic, else unchecked)");
  cmd->add_option("--display-latency-ms", a->display_latency_ms,
                  "Software sync: delay from buffer swap to light on the face")
      ->capture_default_str();
  cmd->add_option("--gamma-compensate", a->gamma_compensate,
                  "--project: send the patterns through a v^(1/G) LUT for a projector of gamma G "
                  "(0 = off)")
      ->capture_default_str();
  cmd->add_option("--calibration", a->calibration,
                  "Rig calibration (required for cameras; default: the synthetic rig's, or the "
                  "replayed session's)");
  cmd->add_flag("--reconstruct", a->reconstruct, "Reconstruct every set live (stats.json)");
  cmd->add_option("--depth-prior", a->depth_prior,
                  "Expected face depth (mm) for spatially unwrapped pattern sets, recorded in "
                  "session.json (default: the replayed session's, the synthetic face's, else "
                  "650)");
  cmd->add_option("--scans", a->scans,
                  "Also write the live range scans (frame_NNNNNN.exr) here (implies "
                  "--reconstruct)");
  cmd->add_flag("--preview", a->preview,
                "Show the reconstructed face live in a window (implies --reconstruct; needs a "
                "display)");
  cmd->add_flag("--preview-optional", a->preview_optional,
                "With --preview: capture without the window when no display can be opened");
  cmd->add_option("--preview-stride", a->preview_stride,
                  "Preview mesh level of detail: every Kth pixel")
      ->capture_default_str();
  cmd->add_option("--queue", a->queue, "Sets queued in front of each stage")->capture_default_str();
  cmd->add_option("--policy", a->policy, "When a queue is full: block, drop-oldest, drop-newest")
      ->capture_default_str();
  add_source_flags(cmd, a->camera, "Camera frame size WxH (synthetic: default 512x512)");
  cmd->add_option("--ict", a->ict, "synthetic: ICT-FaceKit folder");
  cmd->add_option("--expressions", a->expressions, "synthetic: expression track")
      ->capture_default_str();
  cmd->add_option("--seed", a->seed, "synthetic: seed of expressions and noise")
      ->capture_default_str();
  cmd->add_option("--noise", a->noise, "synthetic: camera noise sigma (fraction of the range)")
      ->capture_default_str();
  cmd->add_option("--bit-depth", a->bit_depth, "synthetic: camera bit depth 8, 10, 12, 16")
      ->capture_default_str();
  cmd->add_flag("--cue", a->cue,
                "synthetic: render a white cue frame before every cycle and find the cycles from "
                "the images (--sync cue)");
  cmd->add_flag("--no-ground-truth", a->no_ground_truth,
                "Do not write gt/ (ground truth EXR and landmarks; synthetic, or copied from a "
                "replayed session) and, on replay, do not read it for the live error");
  cmd->add_flag("--no-status", a->quiet_status, "No status line every second");
  cmd->callback([a] { run_capture(*a); });
}

}  // namespace gvkit::tools
