// gvkit play under a virtual X server (xvfb-run): opens a sample, plays 30 frames, writes a
// screenshot; and without any display, fails with a message pointing at gvkit render.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "gvkit/core/image_io.hpp"
#include "player_test_data.hpp"
#include "support/test_support.hpp"

namespace gvkit::player {
namespace {

namespace fs = std::filesystem;
using gvkit::testing::TempDir;

struct ShellRun {
  int exit_code = -1;
  std::string output;
};

ShellRun run_shell(const std::string& command) {
  ShellRun r;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  while (size_t n = std::fread(buf, 1, sizeof(buf), pipe)) r.output.append(buf, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string gvkit_binary() {
  const char* env = std::getenv("GVKIT_BINARY");
  return env ? env : GVKIT_BINARY_PATH;
}

TEST(GuiSmoke, PlaysThirtyFramesUnderXvfbAndTakesAScreenshot) {
  if (run_shell("command -v xvfb-run").exit_code != 0) GTEST_SKIP() << "xvfb-run is not installed";
  TempDir tmp;
  testing::write_face_like_sequence(tmp / "seq", 12, 48);
  const fs::path shot = tmp / "shot.png";
  const ShellRun r = run_shell(
      "xvfb-run -a -s '-screen 0 1024x768x24' " + gvkit_binary() + " play " +
      (tmp / "seq").string() + " --reference " + (tmp / "seq").string() +
      " --shading error --size 800x600 --exit-after-frames 30 --screenshot " + shot.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto image = read_image(shot);
  ASSERT_TRUE(image.is_ok()) << image.status().message();
  EXPECT_EQ(image->size(), cv::Size(800, 600));
  // Not a blank window: the picture has many distinct colours (mesh, panel, timeline).
  cv::Mat grey;
  image->convertTo(grey, CV_32F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(grey.reshape(1), mean, stddev);
  EXPECT_GT(stddev[0], 10.0);
  // The 3D view's middle (left of the 340 px panel, above the timeline) shows the surface.
  const cv::Vec3b middle = image->at<cv::Vec3b>((600 - 110) / 2, (800 - 340) / 2);
  EXPECT_LT(middle[0] + middle[1] + middle[2], 3 * 240) << "background at the view centre";
}

TEST(GuiSmoke, WithoutADisplayPointsAtRender) {
  TempDir tmp;
  testing::write_face_like_sequence(tmp / "seq", 2, 16);
  const ShellRun r = run_shell("env -u DISPLAY -u WAYLAND_DISPLAY " + gvkit_binary() + " play " +
                               (tmp / "seq").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("gvkit render"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace gvkit::player
