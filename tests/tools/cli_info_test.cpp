// The gvkit binary as a user runs it: `gvkit info` on real files and on bad input.
#include <cstdlib>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/image_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::run_gvkit;
using testing::TempDir;

using testing::contains;

TEST(CliInfo, VersionAndHelp) {
  auto version = run_gvkit("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_TRUE(contains(version.output, "gvkit 0.")) << version.output;
  auto help = run_gvkit("info --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_TRUE(contains(help.output, "Describe a file"));
  EXPECT_NE(run_gvkit("").exit_code, 0);
  EXPECT_NE(run_gvkit("no-such-command").exit_code, 0);
}

TEST(CliInfo, DescribesTheSlStudioCalibration) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto r = run_gvkit("info " + (data / "slstudio-skull-2x3" / "calibration.xml").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "SLStudio"));
  EXPECT_TRUE(contains(r.output, "1688x1352"));
  EXPECT_TRUE(contains(r.output, "1824x1140"));
  EXPECT_TRUE(contains(r.output, "2195.120"));    // camera focal length
  EXPECT_TRUE(contains(r.output, "2601.525"));    // projector focal length
  EXPECT_TRUE(contains(r.output, "-0.0580353"));  // camera distortion k1
  EXPECT_TRUE(contains(r.output, "t cam_from_proj"));
}

TEST(CliInfo, DescribesAForeignLayoutWithoutSizes) {
  TempDir dir;
  ASSERT_TRUE(write_file_atomically(dir / "procam.yml",
                                    "%YAML:1.0\n"
                                    "cam_K: [1000, 0, 320, 0, 1000, 240, 0, 0, 1]\n"
                                    "cam_kc: [0, 0, 0, 0, 0]\n"
                                    "proj_K: [1500, 0, 640, 0, 1500, 400, 0, 0, 1]\n"
                                    "proj_kc: [0, 0, 0, 0, 0]\n"
                                    "R: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
                                    "T: [-200, 0, 0]\n")
                  .is_ok());
  auto r = run_gvkit("info " + (dir / "procam.yml").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "procam layout")) << r.output;
  EXPECT_TRUE(contains(r.output, "size not recorded (give --projector-size)")) << r.output;
  EXPECT_TRUE(contains(r.output, "baseline (mm)                200.0000")) << r.output;
  ASSERT_TRUE(write_file_atomically(dir / "odd.yml", "%YAML:1.0\nfocal: 3\n").is_ok());
  auto odd = run_gvkit("info " + (dir / "odd.yml").string());
  EXPECT_NE(odd.exit_code, 0);
  EXPECT_TRUE(contains(odd.output, "keys found: focal")) << odd.output;
}

TEST(CliInfo, DescribesTheIctMesh) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto r = run_gvkit("info " + (data / "ict-facekit" / "generic_neutral_mesh.obj").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "vertices        26719")) << r.output;
  EXPECT_TRUE(contains(r.output, "genus"));
}

TEST(CliInfo, DescribesAnImage) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  auto r = run_gvkit("info " + (data / "slstudio-skull-2x3" / "frame_00.png").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "1688x1352"));
}

// A command that reads no image starts without OpenCV's codecs (opencv_media.hpp): the dynamic
// loader's list of the files it loads names OpenCV's core but neither imgcodecs nor videoio. An
// image still reads, through the plugin; without the plugin the error says what to set.
TEST(CliInfo, StartsWithoutOpenCvCodecsAndLoadsThemForAnImage) {
  ::setenv("LD_DEBUG", "files", 1);
  auto version = run_gvkit("--version");
  ::unsetenv("LD_DEBUG");
  ASSERT_EQ(version.exit_code, 0);
  EXPECT_TRUE(contains(version.output, "libopencv_core")) << "LD_DEBUG gave no file list";
  EXPECT_FALSE(contains(version.output, "libopencv_imgcodecs"));
  EXPECT_FALSE(contains(version.output, "libopencv_videoio"));

  TempDir dir;
  ASSERT_TRUE(write_image(dir / "grey.png", cv::Mat(24, 40, CV_16U, cv::Scalar(1234))).is_ok());
  auto image = run_gvkit("info " + (dir / "grey.png").string());
  ASSERT_EQ(image.exit_code, 0) << image.output;
  EXPECT_TRUE(contains(image.output, "40x24, 1 channel(s), 16-bit, values 1234..1234"))
      << image.output;

  ::setenv("GVKIT_OPENCV_MEDIA", (dir / "missing_plugin.so").c_str(), 1);
  auto missing = run_gvkit("info " + (dir / "grey.png").string());
  ::unsetenv("GVKIT_OPENCV_MEDIA");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_TRUE(contains(missing.output, "missing_plugin.so")) << missing.output;
  EXPECT_TRUE(contains(missing.output, "set GVKIT_OPENCV_MEDIA")) << missing.output;
}

TEST(CliInfo, BadInputGivesOneLineAndNonZeroExit) {
  TempDir dir;
  auto missing = run_gvkit("info " + (dir / "missing.exr").string());
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_TRUE(contains(missing.output, "missing.exr: no such file")) << missing.output;

  ASSERT_TRUE(write_file_atomically(dir / "bad.exr", "garbage").is_ok());
  auto bad = run_gvkit("info " + (dir / "bad.exr").string());
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_TRUE(contains(bad.output, "bad.exr")) << bad.output;

  ASSERT_TRUE(write_file_atomically(dir / "bad.yaml", "%YAML:1.0\ncamera_K: 3\n").is_ok());
  auto calib = run_gvkit("info " + (dir / "bad.yaml").string());
  EXPECT_EQ(calib.exit_code, 1);
  EXPECT_TRUE(contains(calib.output, "camera_K")) << calib.output;

  ASSERT_TRUE(write_file_atomically(dir / "x.weird", "x").is_ok());
  auto weird = run_gvkit("info " + (dir / "x.weird").string());
  EXPECT_EQ(weird.exit_code, 1);
  EXPECT_TRUE(contains(weird.output, "unknown file type"));
}

}  // namespace
}  // namespace gvkit
