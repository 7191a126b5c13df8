// libcamera on a machine without cameras: the manager starts, sees none, and opening a camera
// says so. With GVKIT_TEST_LIBCAMERA=<id or index> set, one more test streams from that camera.
#include "gvkit/capture/libcamera_source.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

namespace gvkit {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(LibcameraSource, NoCamerasIsAClearStatus) {
  auto cameras = list_libcamera_cameras();
  ASSERT_TRUE(cameras.is_ok()) << cameras.status().message();
  if (!cameras->empty()) GTEST_SKIP() << "this machine has a libcamera camera";
  for (const std::string id : {"", "0", "/base/soc/i2c0mux/i2c@1/imx477@1a"}) {
    auto source = FrameSource::create("libcamera:" + id, {});
    ASSERT_FALSE(source.is_ok());
    EXPECT_EQ(source.status().code(), StatusCode::kNotFound);
    EXPECT_TRUE(contains(source.status().message(), "libcamera sees no cameras"))
        << source.status().message();
  }
  // The manager can be started again after the last user let it go.
  EXPECT_TRUE(list_libcamera_cameras().is_ok());
}

TEST(LibcameraSource, BadOptionsAreRejectedFirst) {
  FrameSourceOptions o;
  o.buffer_count = 0;
  auto source = open_libcamera_source("0", o);
  ASSERT_FALSE(source.is_ok());
  EXPECT_EQ(source.status().code(), StatusCode::kInvalidArgument);
}

TEST(LibcameraSource, RealCamera) {
  const char* id = std::getenv("GVKIT_TEST_LIBCAMERA");
  if (!id) GTEST_SKIP() << "set GVKIT_TEST_LIBCAMERA=<camera id or index> to stream from a camera";
  auto source = open_libcamera_source(id, {});
  ASSERT_TRUE(source.is_ok()) << source.status().message();
  Timestamp last{0};
  for (int i = 0; i < 10; ++i) {
    auto frame = (*source)->next();
    ASSERT_TRUE(frame.is_ok()) << frame.status().message();
    ASSERT_TRUE(frame->has_value());
    EXPECT_FALSE((*frame)->image.empty());
    EXPECT_GE((*frame)->timestamp, last);
    last = (*frame)->timestamp;
  }
}

}  // namespace
}  // namespace gvkit
