#include "gvkit/capture/synthetic_session.hpp"

#include <atomic>
#include <cmath>
#include <mutex>

#include <tbb/parallel_for.h>

#include "gvkit/capture/expression_track.hpp"
#include "gvkit/capture/ground_truth.hpp"
#include "gvkit/capture/ict_face_scene.hpp"
#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/capture/projector_gamma.hpp"
#include "gvkit/capture/session_writer.hpp"
#include "gvkit/core/face_landmarks_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/progress.hpp"

namespace gvkit::capture {

Status SyntheticSessionOptions::check() const {
  if (frames < 1 || frames > 1000000) return invalid_argument("frames must be 1..1000000");
  if (!(fps > 0 && fps <= 10000)) return invalid_argument("fps must be in (0, 10000]");
  if (!(gamma_compensation == 0 || (gamma_compensation >= 0.2 && gamma_compensation <= 5)))
    return invalid_argument("gamma compensation must be 0 (off) or in [0.2, 5]");
  GVKIT_RETURN_IF_ERROR(rig.check());
  GVKIT_RETURN_IF_ERROR(render.check());
  if (plain_folder) {
    if (image_format != "png" && image_format != "bmp")
      return invalid_argument("plain-folder image format must be png or bmp, is '" + image_format +
                              "'");
    if (image_format == "bmp" && render.bit_depth != 8)
      return invalid_argument("BMP images hold 8 bits; the camera renders " +
                              std::to_string(render.bit_depth));
    if (calibration_layout == CalibrationFormat::kCameraFiles)
      return invalid_argument("the one-file-per-device calibration layout is not written");
  }
  return Status::ok();
}

nlohmann::json SyntheticSessionOptions::to_json() const {
  return {{"kind", "synthetic"},
          {"model", "ICT-FaceKit generic neutral + blendshapes"},
          {"expressions", expressions},
          {"seed", seed},
          {"head_motion", head_motion},
          {"face_distance_mm", face_distance_mm},
          {"gamma_compensation", gamma_compensation},
          {"rig", rig.to_json()},
          {"render", render.to_json()}};
}

Status write_synthetic_session(const std::filesystem::path& dir,
                               const SyntheticSessionOptions& options) {
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
  std::vector<cv::Mat> images = patterns->generate(projector);
  if (options.gamma_compensation > 0) compensate_gamma(images, options.gamma_compensation);

  SessionInfo info;
  info.pattern = patterns->name();
  info.images_per_frame = patterns->image_count();
  info.fps = options.fps;
  info.width = calibration.camera_width;
  info.height = calibration.camera_height;
  info.bit_depth = options.render.bit_depth;
  info.ground_truth_dir = "gt";
  info.depth_prior_mm = options.face_distance_mm;
  info.source = options.to_json();
  std::unique_ptr<SessionWriter> writer;
  if (options.plain_folder) {
    std::error_code ec;
    std::filesystem::create_directories(dir / "gt", ec);
    if (ec) return io_error(dir.string() + ": cannot create: " + ec.message());
    GVKIT_RETURN_IF_ERROR(
        write_calibration(dir / "calibration.yml", calibration, options.calibration_layout));
  } else {
    GVKIT_ASSIGN_OR_RETURN(writer, SessionWriter::create(dir, info, calibration));
  }
  const int n = patterns->image_count();

  const SyntheticRenderer renderer(calibration, options.render);
  Progress progress("synth", options.frames, options.progress);
  std::mutex error_mutex;
  Status first_error;
  tbb::parallel_for(0, options.frames, [&](int i) {
    const double t = i / options.fps;
    const ExpressionPose pose = track.at(t);
    const SyntheticScene scene = face.scene(pose);
    const SyntheticFrame frame = renderer.render(scene, images, options.seed * 1000003ull + i);
    FringeSet set;
    set.images = frame.images;
    set.index = i;
    set.timestamp = Timestamp(static_cast<int64_t>(std::llround(t * 1e9)));
    Status s;
    if (writer) {
      s = writer->append(set);
    } else {
      for (int k = 0; k < n && s; ++k)
        s = write_image(dir / ("img_" + std::to_string(i * n + k + 1) + "." + options.image_format),
                        set.images[k]);
    }
    if (s)
      s = write_ground_truth_exr(frame_path(dir / "gt", i, ".exr"),
                                 ground_truth_of(frame.truth, scene));
    if (s)
      s = write_face_landmarks(frame_path(dir / "gt", i, ".landmarks.json"),
                               face.landmarks(pose, calibration));
    if (!s) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (first_error) first_error = s.with_context("frame " + std::to_string(i));
    }
    progress.advance();
  });
  progress.finish();
  return first_error;
}

}  // namespace gvkit::capture
