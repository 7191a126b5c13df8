#pragma once
// LandmarkDetector: dlib's HOG frontal face detector and 68-point shape predictor on a grey
// image (e.g. a range scan's texture). The predictor model (about 100 MB, ~1 s to load) is read
// once in create(); detect() is then safe to call from several threads at once.

#include <filesystem>
#include <memory>

#include <opencv2/core.hpp>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

// Where Debian's libdlib-data puts the 68-point model.
inline const char* const kDefaultShapePredictorPath =
    "/usr/share/dlib/shape_predictor_68_face_landmarks.dat";

struct LandmarkDetectorOptions {
  std::filesystem::path model_path = kDefaultShapePredictorPath;
  // Upsample the image this many times (x2 each) before face detection; 0 for 512x512 scans
  // with the face filling a good part of the image, 1 finds faces down to ~40 px.
  int upsample = 0;
  Status check() const;
};

class LandmarkDetector {
 public:
  // Loads the model; fails naming the file when it is missing or not a dlib shape predictor.
  static Result<LandmarkDetector> create(const LandmarkDetectorOptions& options = {});
  ~LandmarkDetector();
  LandmarkDetector(LandmarkDetector&&) noexcept;
  LandmarkDetector& operator=(LandmarkDetector&&) noexcept;

  // 68 points_px (points_mm empty) of the largest face in `image` (CV_8U, or CV_32F in [0, 1];
  // 1 or 3 channels). Fails (failed precondition, "no face found") when the detector finds none.
  Result<FaceLandmarks> detect(const cv::Mat& image) const;
  // The face box of the last successful detection is not kept; this returns all face boxes.
  std::vector<cv::Rect> detect_faces(const cv::Mat& image) const;

 private:
  LandmarkDetector();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gvkit::facemap
