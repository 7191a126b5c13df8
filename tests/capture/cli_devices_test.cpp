// `gvkit devices` as a user runs it on a machine without cameras (these build machines have
// none): it says so for both stacks and succeeds.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::run_gvkit;
using testing::TempDir;

using testing::contains;

TEST(CliDevices, SaysClearlyWhenThereAreNoCameras) {
  TempDir empty_dev;
  auto r = run_gvkit("devices --dev-dir " + empty_dev.path().string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(
      r.output, "V4L2 devices:\n  none: no " + empty_dev.path().string() + "/video* device nodes"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "libcamera cameras:")) << r.output;
  // libcamera looks at the real machine: none here, but a machine with a camera lists it.
  if (!std::filesystem::exists("/dev/video0") && !std::filesystem::exists("/dev/media0"))
    EXPECT_TRUE(contains(r.output, "none: libcamera sees no cameras")) << r.output;
}

TEST(CliDevices, NodesThatAreNotV4l2DevicesAreNamed) {
  TempDir dev;
  std::fclose(std::fopen((dev / "video3").c_str(), "w"));
  std::fclose(std::fopen((dev / "videoX").c_str(), "w"));  // not a video node name
  auto r = run_gvkit("devices --dev-dir " + dev.path().string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(
      contains(r.output, (dev / "video3").string() + ": VIDIOC_QUERYCAP: not a V4L2 device"))
      << r.output;
  EXPECT_FALSE(contains(r.output, "videoX")) << r.output;
}

TEST(CliDevices, ListsTheRealMachine) {
  auto r = run_gvkit("devices");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  if (!std::filesystem::exists("/dev/video0"))
    EXPECT_TRUE(contains(r.output, "none: no /dev/video* device nodes")) << r.output;
}

TEST(CliDevices, HelpDescribesIt) {
  auto r = run_gvkit("devices --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(contains(r.output, "List the cameras"));
}

}  // namespace
}  // namespace gvkit
