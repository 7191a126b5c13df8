#include "gvkit/capture/synthetic_stream.hpp"

#include <chrono>
#include <cmath>
#include <future>
#include <utility>
#include <vector>

#include "gvkit/capture/expression_track.hpp"
#include "gvkit/capture/ict_face_scene.hpp"
#include "gvkit/capture/pattern_set.hpp"

namespace gvkit::capture {

Status SyntheticStreamOptions::check() const {
  if (!(pose_fps > 0 && pose_fps <= 10000))
    return invalid_argument("synthetic stream: pose_fps must be in (0, 10000]");
  if (keep_truth < 1 || keep_truth > 1024)
    return invalid_argument("synthetic stream: keep_truth must be in 1..1024");
  GVKIT_RETURN_IF_ERROR(rig.check());
  GVKIT_RETURN_IF_ERROR(render.check());
  return Status::ok();
}

nlohmann::json SyntheticStreamOptions::to_json() const {
  return {{"kind", "synthetic"},
          {"model", "ICT-FaceKit generic neutral + blendshapes"},
          {"expressions", expressions},
          {"seed", seed},
          {"head_motion", head_motion},
          {"pose_fps", pose_fps},
          {"face_distance_mm", face_distance_mm},
          {"cue", cue},
          {"rig", rig.to_json()},
          {"render", render.to_json()}};
}

namespace {

struct Rendered {
  std::vector<cv::Mat> images;  // frames_per_cycle camera images
  GroundTruth truth;
  double render_ms = 0;
};

}  // namespace

struct SyntheticStream::Impl {
  Impl(IctFaceScene face_in, ExpressionTrack track_in, const Calibration& calibration,
       const RenderOptions& render)
      : face(std::move(face_in)), track(std::move(track_in)), renderer(calibration, render) {}

  IctFaceScene face;
  ExpressionTrack track;
  SyntheticRenderer renderer;
  std::vector<cv::Mat> projector_images;  // cue (white) first when asked, then the fringes

  mutable std::mutex mutex;
  std::map<int64_t, std::shared_future<std::shared_ptr<const Rendered>>> pending;
  std::map<int64_t, GroundTruth> truths;
  double render_ms_sum = 0;
  int64_t renders = 0;
};

SyntheticStream::SyntheticStream(std::unique_ptr<Impl> impl, const SyntheticStreamOptions& options)
    : impl_(std::move(impl)), options_(options) {}

SyntheticStream::~SyntheticStream() {
  // Renders still running hold no reference to the stream's members beyond Impl: wait for them.
  std::map<int64_t, std::shared_future<std::shared_ptr<const Rendered>>> pending;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    pending.swap(impl_->pending);
  }
  for (auto& [j, f] : pending) f.wait();
}

Result<std::shared_ptr<SyntheticStream>> SyntheticStream::create(
    const SyntheticStreamOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  GVKIT_ASSIGN_OR_RETURN(auto patterns, create_pattern_set(options.pattern));
  GVKIT_ASSIGN_OR_RETURN(
      ExpressionTrack track,
      ExpressionTrack::create(options.expressions, options.seed, options.head_motion));
  IctFaceSceneOptions scene_options;
  scene_options.distance_mm = options.face_distance_mm;
  GVKIT_ASSIGN_OR_RETURN(IctFaceScene face, IctFaceScene::load(options.ict_dir, scene_options));
  Calibration calibration = synthetic_calibration(options.rig);
  calibration.fringe_pitch_px = patterns->pitch_px(calibration.projector_width);
  const cv::Size projector(calibration.projector_width, calibration.projector_height);

  auto impl =
      std::make_unique<Impl>(std::move(face), std::move(track), calibration, options.render);
  if (options.cue) impl->projector_images.push_back(cv::Mat(projector, CV_32F, cv::Scalar(1.0)));
  for (cv::Mat& image : patterns->generate(projector)) impl->projector_images.push_back(image);
  std::shared_ptr<SyntheticStream> stream(new SyntheticStream(std::move(impl), options));
  stream->calibration_ = calibration;
  stream->patterns_per_cycle_ = patterns->image_count();
  return stream;
}

Result<cv::Mat> SyntheticStream::frame(int64_t i) {
  GVKIT_CHECK(i >= 0, "synthetic frame index is negative");
  const int64_t cycle = frames_per_cycle();
  const int64_t j = i / cycle;
  Impl* impl = impl_.get();
  const SyntheticStreamOptions options = options_;
  auto launch = [impl, options](int64_t instant) {
    return std::async(std::launch::async,
                      [impl, options, instant] {
                        const auto start = std::chrono::steady_clock::now();
                        const ExpressionPose pose =
                            impl->track.at(static_cast<double>(instant) / options.pose_fps);
                        const SyntheticScene scene = impl->face.scene(pose);
                        SyntheticFrame frame = impl->renderer.render(
                            scene, impl->projector_images,
                            options.seed * 1000003ull + static_cast<uint64_t>(instant));
                        auto out = std::make_shared<Rendered>();
                        out->images = std::move(frame.images);
                        out->truth = ground_truth_of(frame.truth, scene);
                        out->render_ms = std::chrono::duration<double, std::milli>(
                                             std::chrono::steady_clock::now() - start)
                                             .count();
                        return std::shared_ptr<const Rendered>(out);
                      })
        .share();
  };
  std::shared_future<std::shared_ptr<const Rendered>> current;
  std::vector<std::shared_future<std::shared_ptr<const Rendered>>> finished;
  {
    std::lock_guard<std::mutex> lock(impl->mutex);
    // Instants before j are done with (the stream only moves forward).
    while (!impl->pending.empty() && impl->pending.begin()->first < j) {
      finished.push_back(impl->pending.begin()->second);
      impl->pending.erase(impl->pending.begin());
    }
    auto at = impl->pending.find(j);
    if (at == impl->pending.end()) at = impl->pending.emplace(j, launch(j)).first;
    current = at->second;
    if (!impl->pending.count(j + 1)) impl->pending.emplace(j + 1, launch(j + 1));
  }
  finished.clear();  // outside the lock: may wait for a render of a skipped instant
  const std::shared_ptr<const Rendered>& rendered = current.get();
  {
    std::lock_guard<std::mutex> lock(impl->mutex);
    if (!impl->truths.count(j)) {
      impl->truths.emplace(j, rendered->truth);
      impl->render_ms_sum += rendered->render_ms;
      ++impl->renders;
      while (static_cast<int>(impl->truths.size()) > options_.keep_truth)
        impl->truths.erase(impl->truths.begin());
    }
  }
  return rendered->images[static_cast<size_t>(i % cycle)];
}

FrameGenerator SyntheticStream::generator() {
  std::shared_ptr<SyntheticStream> self = shared_from_this();
  return [self](int64_t i) { return self->frame(i); };
}

std::optional<GroundTruth> SyntheticStream::truth(int64_t instant) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  auto at = impl_->truths.find(instant);
  if (at == impl_->truths.end()) return std::nullopt;
  return at->second;
}

FaceLandmarks SyntheticStream::landmarks(int64_t instant) const {
  const ExpressionPose pose = impl_->track.at(static_cast<double>(instant) / options_.pose_fps);
  return impl_->face.landmarks(pose, calibration_);
}

double SyntheticStream::mean_render_ms() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->renders ? impl_->render_ms_sum / static_cast<double>(impl_->renders) : 0.0;
}

}  // namespace gvkit::capture
