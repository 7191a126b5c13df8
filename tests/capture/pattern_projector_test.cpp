// The pattern window under a private Xvfb server (started here with -displayfd, so parallel
// tests never collide): it opens, shows each pattern (read back from the X server), cycles with
// monotonic presentation times; no display, a missing monitor and bad patterns give clear
// Statuses.
#include "gvkit/capture/pattern_projector.hpp"

#include <dlfcn.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <X11/Xlib.h>
#include <X11/Xutil.h>
#undef Status  // Xlib's macro would shadow gvkit::Status

#include <cstdlib>
#include <string>

namespace gvkit {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Starts `Xvfb -displayfd` and points DISPLAY at it; stops it at the end.
class PrivateXvfb {
 public:
  PrivateXvfb() {
    int fds[2];
    if (::pipe(fds) != 0) return;
    pid_t pid = ::fork();
    if (pid == 0) {
      ::close(fds[0]);
      const std::string fd = std::to_string(fds[1]);
      ::execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "320x200x24", "-nolisten",
               "tcp", "-noreset", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(fds[1]);
    pid_ = pid;
    std::string number;  // Xvfb writes "<display>\n", possibly in pieces
    char c;
    while (::read(fds[0], &c, 1) == 1 && c != '\n') number += c;
    ::close(fds[0]);
    if (!number.empty()) display_ = ":" + number;
  }
  ~PrivateXvfb() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  const std::string& display() const { return display_; }

 private:
  pid_t pid_ = -1;
  std::string display_;
};

// What the X server shows in the screen rectangle (x, y, size): the green channel of the
// root window, read through X11 the way a screenshot is (not through OpenGL).
cv::Mat screen_green(const std::string& display, cv::Rect rect) {
  Display* d = XOpenDisplay(display.c_str());
  if (!d) return {};
  XImage* image =
      XGetImage(d, DefaultRootWindow(d), rect.x, rect.y, static_cast<unsigned>(rect.width),
                static_cast<unsigned>(rect.height), AllPlanes, ZPixmap);
  cv::Mat out;
  if (image) {
    out.create(rect.height, rect.width, CV_8U);
    for (int y = 0; y < rect.height; ++y)
      for (int x = 0; x < rect.width; ++x)
        out.at<uint8_t>(y, x) = static_cast<uint8_t>((XGetPixel(image, x, y) & image->green_mask) >>
                                                     __builtin_ctzl(image->green_mask));
    XDestroyImage(image);
  }
  XCloseDisplay(d);
  return out;
}

std::vector<cv::Mat> patterns(cv::Size size) {
  std::vector<cv::Mat> out;
  for (int k = 0; k < 3; ++k) {
    cv::Mat p(size, CV_8U);
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x)
        p.at<uint8_t>(y, x) = static_cast<uint8_t>((x * 4 + y + 60 * k) & 0xff);
    out.push_back(p);
  }
  return out;
}

TEST(PatternProjector, NoDisplayIsAClearStatus) {
  const char* display = std::getenv("DISPLAY");
  const std::string saved = display ? display : "";
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  auto p = PatternProjector::open({});
  ASSERT_FALSE(p.is_ok());
  EXPECT_EQ(p.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_TRUE(contains(p.status().message(), "no display")) << p.status().message();
  ::setenv("DISPLAY", ":gvkit-none-99", 1);  // set but unreachable
  auto q = PatternProjector::open({});
  ASSERT_FALSE(q.is_ok());
  EXPECT_TRUE(contains(q.status().message(), "cannot open the display")) << q.status().message();
  if (display) ::setenv("DISPLAY", saved.c_str(), 1);
}

TEST(PatternProjector, PatternRateMustFitTheRefresh) {
  EXPECT_TRUE(check_pattern_rate(3, 20, 60).is_ok());
  const Status too_fast = check_pattern_rate(4, 30, 60);
  ASSERT_FALSE(too_fast.is_ok());
  EXPECT_TRUE(contains(too_fast.message(), "need 120 patterns/s")) << too_fast.message();
  EXPECT_TRUE(contains(too_fast.message(), "at most 15 cycles/s")) << too_fast.message();
  EXPECT_FALSE(check_pattern_rate(0, 1, 60).is_ok());
}

class ProjectorUnderXvfb : public ::testing::Test {
 protected:
  void SetUp() override {
    // Mesa's software GL driver keeps a few bytes for the life of the process and is unloaded
    // at glfwTerminate(); held open here, LeakSanitizer can name it (see the suppressions).
    static void* mesa = ::dlopen("/usr/lib/x86_64-linux-gnu/dri/swrast_dri.so", RTLD_LAZY);
    static_cast<void>(mesa);
    if (::system("command -v Xvfb >/dev/null 2>&1") != 0) GTEST_SKIP() << "Xvfb is not installed";
    xvfb_ = std::make_unique<PrivateXvfb>();
    ASSERT_FALSE(xvfb_->display().empty()) << "Xvfb did not start";
    ::setenv("DISPLAY", xvfb_->display().c_str(), 1);
  }
  void TearDown() override { xvfb_.reset(); }
  std::unique_ptr<PrivateXvfb> xvfb_;
};

TEST_F(ProjectorUnderXvfb, ShowsEachPatternAndCyclesWithMonotonicTimes) {
  PatternProjectorOptions o;  // fullscreen on monitor 0: Xvfb's 320x200 screen
  auto projector = PatternProjector::open(o);
  ASSERT_TRUE(projector.is_ok()) << projector.status().message();
  PatternProjector& p = **projector;
  EXPECT_EQ(p.size(), cv::Size(320, 200));
  EXPECT_TRUE(contains(p.describe(), "monitor 0")) << p.describe();
  const std::vector<cv::Mat> set = patterns(p.size());
  ASSERT_TRUE(p.set_patterns(set).is_ok());
  for (int k = 0; k < 3; ++k) {
    auto t = p.show(k);
    ASSERT_TRUE(t.is_ok()) << t.status().message();
    const cv::Mat on_screen = screen_green(xvfb_->display(), cv::Rect(0, 0, 320, 200));
    ASSERT_FALSE(on_screen.empty());
    EXPECT_EQ(cv::norm(on_screen, set[static_cast<size_t>(k)], cv::NORM_INF), 0) << "pattern " << k;
  }
  auto shown = p.run_cycles(4, 10);
  ASSERT_TRUE(shown.is_ok());
  ASSERT_EQ(shown->size(), 12u);
  for (size_t i = 0; i < shown->size(); ++i) {
    EXPECT_EQ((*shown)[i].cycle, 10 + static_cast<int64_t>(i / 3));
    EXPECT_EQ((*shown)[i].pattern, static_cast<int>(i % 3));
    if (i > 0) EXPECT_GT((*shown)[i].presented, (*shown)[i - 1].presented);
  }
}

TEST_F(ProjectorUnderXvfb, BadMonitorAndBadPatterns) {
  PatternProjectorOptions o;
  o.monitor = 3;
  auto none = PatternProjector::open(o);
  ASSERT_FALSE(none.is_ok());
  EXPECT_TRUE(contains(none.status().message(), "no monitor 3; connected: 0 '"))
      << none.status().message();

  o = {};
  o.fullscreen = false;
  o.window_width = 64;
  o.window_height = 32;
  auto projector = PatternProjector::open(o);
  ASSERT_TRUE(projector.is_ok()) << projector.status().message();
  EXPECT_TRUE(contains((*projector)->set_patterns({}).message(), "empty"));
  const Status mixed = (*projector)
                           ->set_patterns({cv::Mat(8, 8, CV_8U, cv::Scalar(1)),
                                           cv::Mat(4, 8, CV_8U, cv::Scalar(1))});
  EXPECT_TRUE(contains(mixed.message(), "pattern 1: size 8x4 differs")) << mixed.message();
  const Status floats = (*projector)->set_patterns({cv::Mat(8, 8, CV_32F, cv::Scalar(1))});
  EXPECT_EQ(floats.code(), StatusCode::kUnsupported);
  // A 16-bit pattern is shown at its top 8 bits, stretched to the window.
  ASSERT_TRUE((*projector)->set_patterns({cv::Mat(4, 4, CV_16U, cv::Scalar(200 * 257))}).is_ok());
  ASSERT_TRUE((*projector)->show(0).is_ok());
  EXPECT_EQ((*projector)->size(), cv::Size(64, 32));
}

}  // namespace
}  // namespace gvkit

// Allocations Mesa's GL driver and X libraries keep until exit are theirs, not gvkit's.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:swrast_dri.so\nleak:libGLX_mesa.so\nleak:libglapi.so\nleak:libLLVM\n";
}
