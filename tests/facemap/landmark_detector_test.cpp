// dlib landmark detection on a real photograph shipped with dlib, and the no-face case.
#include "gvkit/facemap/landmark_detector.hpp"

#include <filesystem>

#include <gtest/gtest.h>

#include "gvkit/core/image_io.hpp"

namespace gvkit::facemap {
namespace {

const char* const kPhoto = "/usr/share/doc/libdlib19.1/examples/faces/2008_002506.jpg";

class LandmarkDetectorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!std::filesystem::exists(kDefaultShapePredictorPath)) return;
    auto d = LandmarkDetector::create();
    ASSERT_TRUE(d.is_ok()) << d.status().message();
    detector_ = new LandmarkDetector(std::move(d).value());
  }
  static void TearDownTestSuite() {
    delete detector_;
    detector_ = nullptr;
  }
  static LandmarkDetector* detector_;
};
LandmarkDetector* LandmarkDetectorTest::detector_ = nullptr;

TEST_F(LandmarkDetectorTest, Finds68PointsInsideTheFaceBox) {
  if (!detector_ || !std::filesystem::exists(kPhoto))
    GTEST_SKIP() << "dlib model or example photo absent (packages libdlib-data, libdlib19.1)";
  const Result<cv::Mat> read = read_image(kPhoto, /*grey=*/true);
  ASSERT_TRUE(read.is_ok()) << read.status().message();
  const cv::Mat& image = *read;
  const auto faces = detector_->detect_faces(image);
  ASSERT_GE(faces.size(), 1u);
  auto landmarks = detector_->detect(image);
  ASSERT_TRUE(landmarks.is_ok()) << landmarks.status().message();
  ASSERT_EQ(landmarks->points_px.size(), 68u);
  // The largest box, grown by a quarter on each side, holds every point.
  cv::Rect box = faces[0];
  for (const auto& f : faces)
    if (f.area() > box.area()) box = f;
  const cv::Rect grown(box.x - box.width / 4, box.y - box.height / 4, box.width * 3 / 2,
                       box.height * 3 / 2);
  for (const auto& p : landmarks->points_px) EXPECT_TRUE(grown.contains(p)) << p;
  // Anatomy: the subject's right eye (36-41) is left of the left eye in the image, the nose tip
  // between the eyes and the mouth.
  EXPECT_LT(landmarks->points_px[36].x, landmarks->points_px[45].x);
  EXPECT_GT(landmarks->points_px[30].y, landmarks->points_px[36].y);
  EXPECT_LT(landmarks->points_px[30].y, landmarks->points_px[57].y);
}

TEST_F(LandmarkDetectorTest, NoFaceIsAnError) {
  if (!detector_) GTEST_SKIP() << "dlib model absent (package libdlib-data)";
  const cv::Mat blank(200, 200, CV_32F, cv::Scalar(0.5f));
  auto landmarks = detector_->detect(blank);
  ASSERT_FALSE(landmarks.is_ok());
  EXPECT_NE(landmarks.status().message().find("no face"), std::string::npos);
}

TEST(LandmarkDetector, MissingModelIsAnErrorNamingTheFile) {
  LandmarkDetectorOptions options;
  options.model_path = "/nonexistent/model.dat";
  auto detector = LandmarkDetector::create(options);
  ASSERT_FALSE(detector.is_ok());
  EXPECT_NE(detector.status().message().find("/nonexistent/model.dat"), std::string::npos);
}

}  // namespace
}  // namespace gvkit::facemap
