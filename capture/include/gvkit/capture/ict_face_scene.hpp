#pragma once
// The ICT-FaceKit head as a synthetic scene: the face area plus the rest of the head (occluders),
// mouth interior, teeth and eyeballs, with per-region albedo that makes the texture read as a
// face (skin, darker lips, brows and lash lines, bright sclera, dark iris and pupil), posed
// facing the camera. Eyelashes and the transparent eye meshes are left out.

#include <filesystem>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/capture/expression_track.hpp"
#include "gvkit/capture/synthetic_renderer.hpp"
#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::capture {

struct IctFaceSceneOptions {
  double distance_mm = 650;  // depth of the landmarks' centroid in front of the camera
  Status check() const;
};

class IctFaceScene {
 public:
  // Loads the model and the blendshapes the expression tracks use from the ICT folder. Fails
  // naming the file when the model cannot be read.
  static Result<IctFaceScene> load(const std::filesystem::path& ict_dir,
                                   const IctFaceSceneOptions& options = {});

  // The posed mesh (camera frame). triangle_source holds the model's polygon index.
  SyntheticScene scene(const ExpressionPose& pose) const;
  // Model vertex positions of a pose in the camera frame (all kVertexCount vertices).
  std::vector<cv::Vec3d> positions_mm(const ExpressionPose& pose) const;
  // The 68 landmarks of a pose: points_mm in the camera frame, points_px projected with the
  // calibration (no occlusion test).
  FaceLandmarks landmarks(const ExpressionPose& pose, const Calibration& calibration) const;

  const IctFaceModel& model() const { return model_; }
  const std::vector<float>& albedo() const { return albedo_; }
  const std::vector<cv::Vec3i>& triangles() const { return triangles_; }

 private:
  IctFaceModel model_;
  IctFaceSceneOptions options_;
  std::vector<float> albedo_;
  std::vector<cv::Vec3i> triangles_;
  std::vector<int> triangle_polygon_;
  cv::Vec3d centre_mm_;  // landmark centroid of the neutral model (model frame)
};

}  // namespace gvkit::capture
