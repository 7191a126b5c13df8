// Bad input to reconstruction: a Status naming the frame and the problem, or an empty scan with
// a warning for frames without signal.
#include <gtest/gtest.h>

#include "gvkit/capture/reconstructor.hpp"
#include "gvkit/capture/synthetic_rig.hpp"

namespace gvkit::capture {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    SyntheticRigOptions o;
    o.camera_width = 48;
    o.camera_height = 40;
    calibration_ = synthetic_calibration(o);
    auto r = Reconstructor::create(calibration_);
    ASSERT_TRUE(r);
    reconstructor_.emplace(std::move(*r));
    auto p = create_pattern_set("psp3-f16");
    ASSERT_TRUE(p);
    patterns_ = std::move(*p);
  }
  FringeSet frame(int count, int value, int depth = CV_8U) const {
    FringeSet f;
    f.index = 7;
    for (int k = 0; k < count; ++k) f.images.emplace_back(40, 48, depth, cv::Scalar(value));
    return f;
  }
  Calibration calibration_;
  std::optional<Reconstructor> reconstructor_;
  std::unique_ptr<PatternSet> patterns_;
};

TEST_F(BadInput, WrongImageCountNamesFrameAndCounts) {
  auto r = reconstructor_->reconstruct(frame(4, 100), *patterns_);
  ASSERT_FALSE(r);
  EXPECT_TRUE(contains(r.status().message(), "frame 7")) << r.status().message();
  EXPECT_TRUE(contains(r.status().message(), "needs 3 images, got 4")) << r.status().message();
}

TEST_F(BadInput, MixedSizesNameTheImage) {
  FringeSet f = frame(3, 100);
  f.images[2] = cv::Mat(40, 47, CV_8U, cv::Scalar(1));
  auto r = reconstructor_->reconstruct(f, *patterns_);
  ASSERT_FALSE(r);
  EXPECT_TRUE(contains(r.status().message(), "frame 7")) << r.status().message();
  EXPECT_TRUE(contains(r.status().message(), "image 2")) << r.status().message();
}

TEST_F(BadInput, MixedDepthsAndFloatImagesAreRejected) {
  FringeSet f = frame(3, 100);
  f.images[1] = cv::Mat(40, 48, CV_16U, cv::Scalar(1));
  EXPECT_FALSE(reconstructor_->reconstruct(f, *patterns_));
  FringeSet g = frame(3, 100);
  g.images[0] = cv::Mat(40, 48, CV_32F, cv::Scalar(NAN));
  auto r = reconstructor_->reconstruct(g, *patterns_);
  ASSERT_FALSE(r);
  EXPECT_TRUE(contains(r.status().message(), "image 0")) << r.status().message();
}

TEST_F(BadInput, SizeDifferentFromCalibration) {
  FringeSet f;
  f.index = 3;
  for (int k = 0; k < 3; ++k) f.images.emplace_back(41, 48, CV_8U, cv::Scalar(1));
  auto r = reconstructor_->reconstruct(f, *patterns_);
  ASSERT_FALSE(r);
  EXPECT_TRUE(contains(r.status().message(), "frame 3")) << r.status().message();
  EXPECT_TRUE(contains(r.status().message(), "camera size")) << r.status().message();
}

TEST_F(BadInput, DarkAndSaturatedFramesGiveEmptyScans) {
  for (int value : {0, 255}) {
    auto r = reconstructor_->reconstruct(frame(3, value), *patterns_);
    ASSERT_TRUE(r) << r.status().message();
    EXPECT_EQ(cv::countNonZero(r->valid), 0);
    EXPECT_EQ(r->index, 7);
    EXPECT_TRUE(r->check()) << r->check().message();
  }
  // 16-bit saturation too.
  auto r = reconstructor_->reconstruct(frame(3, 65535, CV_16U), *patterns_);
  ASSERT_TRUE(r);
  EXPECT_EQ(cv::countNonZero(r->valid), 0);
}

TEST_F(BadInput, EmptyFringeSet) {
  FringeSet f;
  auto r = reconstructor_->reconstruct(f, *patterns_);
  EXPECT_FALSE(r);
}

TEST(ReconstructOptions, OutOfRange) {
  ReconstructOptions o;
  o.min_depth_mm = 100;
  o.max_depth_mm = 50;
  EXPECT_FALSE(o.check());
  o = {};
  o.depth_prior_mm = -1;
  EXPECT_FALSE(Reconstructor::create(synthetic_calibration(), o));
}

}  // namespace
}  // namespace gvkit::capture
