#include "gvkit/facemap/landmark_detector.hpp"

#include <algorithm>
#include <exception>
#include <future>
#include <string>

#include <dlib/image_processing.h>
#include <dlib/image_processing/frontal_face_detector.h>
#include <dlib/opencv/cv_image.h>
#include <opencv2/imgproc.hpp>

namespace gvkit::facemap {

Status LandmarkDetectorOptions::check() const {
  if (upsample < 0 || upsample > 3)
    return invalid_argument("landmark detector: upsample must be in [0, 3], got " +
                            std::to_string(upsample));
  return Status::ok();
}

struct LandmarkDetector::Impl {
  dlib::frontal_face_detector face_detector;  // copied per call: not safe to share
  dlib::shape_predictor predictor;            // const use is thread-safe
  int upsample = 0;
};

LandmarkDetector::LandmarkDetector() : impl_(std::make_unique<Impl>()) {}
LandmarkDetector::~LandmarkDetector() = default;
LandmarkDetector::LandmarkDetector(LandmarkDetector&&) noexcept = default;
LandmarkDetector& LandmarkDetector::operator=(LandmarkDetector&&) noexcept = default;

Result<LandmarkDetector> LandmarkDetector::create(const LandmarkDetectorOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  const std::string path = options.model_path.string();
  if (!std::filesystem::exists(options.model_path))
    return not_found(path + ": dlib shape predictor model not found (package libdlib-data)");
  LandmarkDetector detector;
  // dlib's face detector is decompressed from the text embedded in dlib, about as long as reading
  // the shape predictor's file: the two load side by side.
  std::future<dlib::frontal_face_detector> face_detector =
      std::async(std::launch::async, [] { return dlib::get_frontal_face_detector(); });
  try {
    dlib::deserialize(path) >> detector.impl_->predictor;
  } catch (const std::exception& e) {
    return corrupt_data(path + ": not a dlib shape predictor: " + e.what());
  }
  if (detector.impl_->predictor.num_parts() != FaceLandmarks::kCount)
    return unsupported(path + ": model has " +
                       std::to_string(detector.impl_->predictor.num_parts()) +
                       " parts, expected 68");
  detector.impl_->face_detector = face_detector.get();
  detector.impl_->upsample = options.upsample;
  return detector;
}

namespace {

cv::Mat to_grey8(const cv::Mat& image) {
  GVKIT_CHECK(!image.empty(), "landmark detector: empty image");
  cv::Mat grey;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else
    grey = image;
  if (grey.depth() == CV_8U) return grey;
  cv::Mat out;
  grey.convertTo(out, CV_8U, grey.depth() == CV_16U ? 1.0 / 257.0 : 255.0);
  return out;
}

}  // namespace

std::vector<cv::Rect> LandmarkDetector::detect_faces(const cv::Mat& image) const {
  const cv::Mat grey = to_grey8(image);
  dlib::cv_image<unsigned char> dimg(grey);
  dlib::array2d<unsigned char> scaled;
  dlib::assign_image(scaled, dimg);
  for (int k = 0; k < impl_->upsample; ++k) dlib::pyramid_up(scaled);
  dlib::frontal_face_detector detector = impl_->face_detector;
  const std::vector<dlib::rectangle> boxes = detector(scaled);
  const double s = 1.0 / (1 << impl_->upsample);
  std::vector<cv::Rect> out;
  for (const auto& b : boxes)
    out.emplace_back(
        cv::Point(static_cast<int>(b.left() * s), static_cast<int>(b.top() * s)),
        cv::Point(static_cast<int>((b.right() + 1) * s), static_cast<int>((b.bottom() + 1) * s)));
  return out;
}

Result<FaceLandmarks> LandmarkDetector::detect(const cv::Mat& image) const {
  const std::vector<cv::Rect> faces = detect_faces(image);
  if (faces.empty()) return failed_precondition("no face found");
  const cv::Rect box =
      *std::max_element(faces.begin(), faces.end(),
                        [](const cv::Rect& a, const cv::Rect& b) { return a.area() < b.area(); });
  const cv::Mat grey = to_grey8(image);
  dlib::cv_image<unsigned char> dimg(grey);
  const dlib::full_object_detection shape = impl_->predictor(
      dimg, dlib::rectangle(box.x, box.y, box.x + box.width - 1, box.y + box.height - 1));
  FaceLandmarks landmarks;
  landmarks.points_px.reserve(FaceLandmarks::kCount);
  for (unsigned k = 0; k < shape.num_parts(); ++k)
    landmarks.points_px.emplace_back(static_cast<float>(shape.part(k).x()),
                                     static_cast<float>(shape.part(k).y()));
  return landmarks;
}

}  // namespace gvkit::facemap
