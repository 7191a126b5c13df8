// `gvkit capture` as a user runs it: the synthetic rig captured into a session (bit-exact with
// `gvkit synth`), reconstructed live with accuracy against the ground truth, opened by
// `gvkit reconstruct` and SessionReader, replayed from the session folder (file:), found by
// its cue frames; the preview with and without a display; bad options exit != 0 with a message.
#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "gvkit/capture/session_reader.hpp"
#include "gvkit/capture/synthetic_rig.hpp"
#include "gvkit/core/calibration_io.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
namespace fs = std::filesystem;
using testing::run_gvkit;
using testing::TempDir;

using testing::contains;

// The image of frame i, pattern k of a session.
cv::Mat image_of(const capture::SessionReader& s, size_t i, int k) {
  auto set = s.read_frame(i);
  EXPECT_TRUE(set.is_ok()) << set.status().message();
  return set.is_ok() ? set->images[static_cast<size_t>(k)] : cv::Mat();
}

double max_difference(const capture::SessionReader& a, const capture::SessionReader& b) {
  double worst = 0;
  EXPECT_EQ(a.frame_count(), b.frame_count());
  for (size_t i = 0; i < std::min(a.frame_count(), b.frame_count()); ++i)
    for (int k = 0; k < a.info().images_per_frame; ++k)
      worst = std::max(worst, cv::norm(image_of(a, i, k), image_of(b, i, k), cv::NORM_INF));
  return worst;
}

TEST(CliLiveCapture, SyntheticCaptureRecordsReconstructsAndReplays) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  TempDir dir;
  const std::string ict = " --ict " + (data / "ict-facekit").string();
  const std::string session = (dir / "s").string();
  // mf3-f16-f1 (absolute phase): at this small size a spatially unwrapped set may take a wrong
  // period for a whole region, which is about the pattern, not the capture.
  auto c = run_gvkit(
      "capture --source synthetic: --pattern mf3-f16-f1 --frames 3 --size 128x96 "
      "--reconstruct --no-status -o " +
      session + ict);
  ASSERT_EQ(c.exit_code, 0) << c.output;
  EXPECT_TRUE(contains(c.output, "captured 3 sets")) << c.output;

  // A session SessionReader opens, with ground truth; the images are those `gvkit synth` renders.
  auto s = capture::SessionReader::open(session);
  ASSERT_TRUE(s.is_ok()) << s.status().message();
  ASSERT_EQ(s->frame_count(), 3u);
  EXPECT_EQ(s->info().pattern, "mf3-f16-f1");
  EXPECT_EQ(s->info().width, 128);
  EXPECT_EQ(s->info().dropped_frames, 0);
  EXPECT_TRUE(s->ground_truth_path(2).has_value());
  EXPECT_TRUE(fs::exists(dir / "s" / "gt" / "frame_000002.landmarks.json"));
  auto synth = run_gvkit("synth -o " + (dir / "synth").string() +
                         " --frames 3 --size 128x96 --pattern mf3-f16-f1 --no-progress" + ict);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  auto reference = capture::SessionReader::open(dir / "synth");
  ASSERT_TRUE(reference.is_ok());
  EXPECT_EQ(max_difference(*s, *reference), 0.0);

  // Live reconstruction against the synthetic ground truth.
  auto stats = read_json(dir / "s" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  const auto& live = (*stats)["summary"];
  EXPECT_EQ(live["sets_recorded"], 3);
  EXPECT_EQ(live["reconstructed"], 3);
  EXPECT_EQ(live["cycles_dropped_by_sync"], 0);
  EXPECT_EQ(live["sync"], "tagged");
  EXPECT_GT(live["mean_valid_share"].get<double>(), 0.1);
  EXPECT_LT(live["face_interior_rms_mm"].get<double>(), 0.3);
  EXPECT_GT(live["face_interior_valid_share"].get<double>(), 0.9);
  EXPECT_TRUE(live["stages"].contains("reconstruct"));

  // `gvkit reconstruct` opens the session and measures the same error.
  auto r =
      run_gvkit("reconstruct " + session + " -o " + (dir / "scans").string() + " --no-progress");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto rstats = read_json(dir / "scans" / "stats.json");
  ASSERT_TRUE(rstats.is_ok());
  EXPECT_NEAR((*rstats)["summary"]["face_interior_rms_mm"].get<double>(),
              live["face_interior_rms_mm"].get<double>(), 1e-6);

  // Replay of the session folder: the same fringe sets, bit-exact, with their ground truth.
  auto replay = run_gvkit("capture --source file:" + session + " --reconstruct --no-status -o " +
                          (dir / "replay").string());
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  auto back = capture::SessionReader::open(dir / "replay");
  ASSERT_TRUE(back.is_ok()) << back.status().message();
  EXPECT_EQ(back->info().pattern, "mf3-f16-f1");
  EXPECT_EQ(max_difference(*s, *back), 0.0);
  EXPECT_TRUE(back->ground_truth_path(1).has_value());
  auto replay_stats = read_json(dir / "replay" / "stats.json");
  ASSERT_TRUE(replay_stats.is_ok());
  EXPECT_NEAR((*replay_stats)["summary"]["face_interior_rms_mm"].get<double>(),
              live["face_interior_rms_mm"].get<double>(), 1e-6);

  // --no-ground-truth on replay: the same sets recorded and reconstructed, but gt/ is neither
  // copied nor read for the live error (the live configuration without an evaluation).
  auto bare =
      run_gvkit("capture --source file:" + session +
                " --reconstruct --no-ground-truth --no-status -o " + (dir / "bare").string());
  ASSERT_EQ(bare.exit_code, 0) << bare.output;
  auto bare_back = capture::SessionReader::open(dir / "bare");
  ASSERT_TRUE(bare_back.is_ok()) << bare_back.status().message();
  EXPECT_EQ(max_difference(*s, *bare_back), 0.0);
  EXPECT_FALSE(bare_back->ground_truth_path(1).has_value());
  auto bare_stats = read_json(dir / "bare" / "stats.json");
  ASSERT_TRUE(bare_stats.is_ok());
  EXPECT_EQ((*bare_stats)["summary"]["reconstructed"], (*replay_stats)["summary"]["reconstructed"]);
  EXPECT_FALSE((*bare_stats)["summary"].contains("face_interior_rms_mm"));
  EXPECT_EQ((*bare_stats)["summary"]["record_writes"]["sets_written"], 3);

  // A write that fails on the record writers' threads fails the capture with the file's name;
  // what was written still opens.
  fs::create_directories(dir / "broken" / "frames" / "frame_000001_k0.png" / "x");
  auto broken = run_gvkit("capture --source file:" + session +
                          " --no-ground-truth --no-status -o " + (dir / "broken").string());
  EXPECT_NE(broken.exit_code, 0) << broken.output;
  EXPECT_TRUE(contains(broken.output, "frame_000001_k0.png")) << broken.output;
  auto partial = capture::SessionReader::open(dir / "broken");
  ASSERT_TRUE(partial.is_ok()) << partial.status().message();
  EXPECT_GE(partial->frame_count(), 1u);
  EXPECT_LE(partial->frame_count(), 2u);
}

TEST(CliLiveCapture, CueFramesFindTheCyclesFromTheImages) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  TempDir dir;
  const std::string ict = " --ict " + (data / "ict-facekit").string();
  auto tagged = run_gvkit(
      "capture --source synthetic: --pattern psp3-f16 --frames 2 --size 96x64 "
      "--no-status -o " +
      (dir / "tagged").string() + ict);
  ASSERT_EQ(tagged.exit_code, 0) << tagged.output;
  auto cue = run_gvkit(
      "capture --source synthetic: --pattern psp3-f16 --frames 2 --size 96x64 "
      "--cue --no-status -o " +
      (dir / "cue").string() + ict);
  ASSERT_EQ(cue.exit_code, 0) << cue.output;
  EXPECT_TRUE(contains(cue.output, "cue sync, 4 frames per set")) << cue.output;
  auto a = capture::SessionReader::open(dir / "tagged");
  auto b = capture::SessionReader::open(dir / "cue");
  ASSERT_TRUE(a.is_ok() && b.is_ok());
  EXPECT_EQ(max_difference(*a, *b), 0.0);  // the same fringe images, paired the same way
  EXPECT_EQ(b->info().dropped_frames, 0);
  EXPECT_EQ(b->info().source["sync"], "cue");
}

TEST(CliLiveCapture, PreviewNeedsADisplayUnlessOptional) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  TempDir dir;
  const std::string common =
      "capture --source synthetic: --pattern psp3-f16 --frames 2 --size 64x48 --no-status --ict " +
      (data / "ict-facekit").string() + " --preview -o ";
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  const std::string saved_display = display ? display : "", saved_wayland = wayland ? wayland : "";
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  auto none = run_gvkit(common + (dir / "a").string());
  auto optional = run_gvkit(common + (dir / "b").string() + " --preview-optional");
  // The projector window needs a display too.
  fs::create_directories(dir / "images");
  for (int i = 0; i < 3; ++i)
    ASSERT_TRUE(write_image(dir / "images" / ("frame_00000" + std::to_string(i) + ".png"),
                            cv::Mat(8, 8, CV_8U, cv::Scalar(9)))
                    .is_ok());
  ASSERT_TRUE(write_calibration(dir / "rig.yaml", capture::synthetic_calibration()).is_ok());
  auto project = run_gvkit("capture --source file:" + (dir / "images").string() +
                           " --pattern psp3-f16 --project 0 --calibration " +
                           (dir / "rig.yaml").string() + " -o " + (dir / "c").string());
  if (display) ::setenv("DISPLAY", saved_display.c_str(), 1);
  if (wayland) ::setenv("WAYLAND_DISPLAY", saved_wayland.c_str(), 1);
  EXPECT_NE(none.exit_code, 0);
  EXPECT_TRUE(contains(none.output, "--preview needs a display")) << none.output;
  EXPECT_TRUE(contains(none.output, "--preview-optional")) << none.output;
  EXPECT_FALSE(fs::exists(dir / "a" / "session.json"));  // nothing started
  ASSERT_EQ(optional.exit_code, 0) << optional.output;
  EXPECT_TRUE(contains(optional.output, "capturing without the preview")) << optional.output;
  EXPECT_TRUE(capture::SessionReader::open(dir / "b").is_ok());
  EXPECT_NE(project.exit_code, 0);
  EXPECT_TRUE(contains(project.output, "DISPLAY")) << project.output;
  EXPECT_FALSE(fs::exists(dir / "c" / "session.json"));
}

#ifdef GVKIT_WITH_PLAYER
TEST(CliLiveCapture, PreviewShowsTheReconstructionsUnderXvfb) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed";
  TempDir dir;
  // run_gvkit runs GVKIT_BINARY: put xvfb-run in front through the shell.
  const char* env = std::getenv("GVKIT_BINARY");
  const std::string binary = env ? env : GVKIT_BINARY_PATH;
  const std::string command =
      "xvfb-run -a -s '-screen 0 1024x768x24' " + binary +
      " capture --source synthetic: --pattern psp3-f16 --frames 3 --size 64x48 --no-status "
      "--preview --ict " +
      (data / "ict-facekit").string() + " -o " + (dir / "p").string() + " 2>&1";
  std::string output;
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char buffer[4096];
  while (size_t n = std::fread(buffer, 1, sizeof(buffer), pipe)) output.append(buffer, n);
  const int status = ::pclose(pipe);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << output;
  auto stats = read_json(dir / "p" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["summary"]["preview_pushed"], 3);
  EXPECT_EQ((*stats)["summary"]["reconstructed"], 3);
}
#endif

TEST(CliLiveCapture, ProjectedPatternsPairWithFramesBySoftwareSyncUnderXvfb) {
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed";
  TempDir dir;
  // The camera: a folder of images replayed in real time at 15 frames/s (--fps 5 x 3 patterns);
  // the patterns go fullscreen on the virtual screen and frames pair by presentation time.
  fs::create_directories(dir / "images");
  for (int i = 0; i < 150; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%06d.png", i);
    ASSERT_TRUE(
        write_image(dir / "images" / name, cv::Mat(12, 16, CV_8U, cv::Scalar(i % 256))).is_ok());
  }
  ASSERT_TRUE(write_calibration(dir / "rig.yaml", capture::synthetic_calibration()).is_ok());
  const char* env = std::getenv("GVKIT_BINARY");
  const std::string binary = env ? env : GVKIT_BINARY_PATH;
  const std::string command = "xvfb-run -a -s '-screen 0 640x480x24' " + binary +
                              " capture --source file:" + (dir / "images").string() +
                              " --pattern psp3-f16 --project 0 --fps 5 --frames 3 --no-status "
                              "--calibration " +
                              (dir / "rig.yaml").string() + " -o " + (dir / "s").string() +
                              " >/dev/null 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0);
  auto s = capture::SessionReader::open(dir / "s");
  ASSERT_TRUE(s.is_ok()) << s.status().message();
  EXPECT_EQ(s->frame_count(), 3u);
  EXPECT_EQ(s->info().source["sync"], "software");
  // Each set holds three consecutive camera frames (one per pattern, in order).
  for (size_t i = 0; i < s->frame_count(); ++i) {
    auto set = s->read_frame(i);
    ASSERT_TRUE(set.is_ok());
    const int first = set->images[0].at<uint8_t>(0, 0);
    for (int k = 1; k < 3; ++k)
      EXPECT_GT(set->images[static_cast<size_t>(k)].at<uint8_t>(0, 0), first);
  }
}

TEST(CliLiveCapture, KilledCaptureLeavesASessionThatOpensAndReplays) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  TempDir dir;
  const char* env = std::getenv("GVKIT_BINARY");
  const std::string binary = env ? env : GVKIT_BINARY_PATH;
  const fs::path session = dir / "s", pid_file = dir / "pid";
  const std::string command =
      binary + " capture --source synthetic: --pattern psp3-f16 --size 64x48 --no-status --ict " +
      (data / "ict-facekit").string() + " -o " + session.string() +
      " >/dev/null 2>&1 & echo $! > " + pid_file.string();
  ASSERT_EQ(std::system(command.c_str()), 0);
  FILE* f = std::fopen(pid_file.c_str(), "r");
  ASSERT_NE(f, nullptr);
  long pid = 0;
  ASSERT_EQ(std::fscanf(f, "%ld", &pid), 1);
  std::fclose(f);
  // Kill it once a few sets are listed (it would run until stopped otherwise).
  size_t listed = 0;
  for (int i = 0; i < 600 && listed < 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (auto s = capture::SessionReader::open(session)) listed = s->frame_count();
  }
  ::kill(static_cast<pid_t>(pid), SIGKILL);
  ASSERT_GE(listed, 3u);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  auto s = capture::SessionReader::open(session);
  ASSERT_TRUE(s.is_ok()) << s.status().message();
  for (size_t i = 0; i < s->frame_count(); ++i) EXPECT_TRUE(s->read_frame(i).is_ok());
  auto replay = run_gvkit("capture --source file:" + session.string() + " --no-status -o " +
                          (dir / "replay").string());
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  auto back = capture::SessionReader::open(dir / "replay");
  ASSERT_TRUE(back.is_ok());
  EXPECT_EQ(back->frame_count(), s->frame_count());
}

TEST(CliLiveCapture, BadOptionsExitNonZeroWithAMessage) {
  TempDir dir;
  const std::string out = " -o " + (dir / "x").string();
  auto scheme = run_gvkit("capture --source http://cam --pattern psp3-f16" + out);
  EXPECT_NE(scheme.exit_code, 0);
  EXPECT_TRUE(contains(scheme.output, "unknown scheme 'http'")) << scheme.output;
  auto device = run_gvkit("capture --source v4l2:/dev/video-gvkit-none --pattern psp3-f16" + out);
  EXPECT_NE(device.exit_code, 0);
  EXPECT_TRUE(contains(device.output, "/dev/video-gvkit-none: open: no such device"))
      << device.output;
  auto pattern = run_gvkit("capture --source synthetic: --pattern psp2-f9" + out);
  EXPECT_NE(pattern.exit_code, 0);
  EXPECT_TRUE(contains(pattern.output, "psp2-f9")) << pattern.output;
  auto both =
      run_gvkit("capture --source synthetic: --pattern psp3-f16 --frames 3 --seconds 2" + out);
  EXPECT_NE(both.exit_code, 0);
  EXPECT_TRUE(contains(both.output, "--seconds")) << both.output;
  // 12 images x 30 sets/s = 360 patterns/s; the synthetic projector shows 120.
  auto rate = run_gvkit("capture --source synthetic: --pattern mf4-f64-f8-f1 --fps 30" + out);
  EXPECT_NE(rate.exit_code, 0);
  EXPECT_TRUE(contains(rate.output, "360 patterns/s")) << rate.output;
  EXPECT_TRUE(contains(rate.output, "at most 10 cycles/s")) << rate.output;
  auto sync = run_gvkit("capture --source synthetic: --pattern psp3-f16 --sync software" + out);
  EXPECT_NE(sync.exit_code, 0);
  EXPECT_TRUE(contains(sync.output, "--project")) << sync.output;
  fs::create_directories(dir / "images");
  ASSERT_TRUE(write_image(dir / "images" / "frame_000000.png", cv::Mat(8, 8, CV_8U, cv::Scalar(9)))
                  .is_ok());
  auto calibration =
      run_gvkit("capture --source file:" + (dir / "images").string() + " --pattern psp3-f16" + out);
  EXPECT_NE(calibration.exit_code, 0);
  EXPECT_TRUE(contains(calibration.output, "--calibration")) << calibration.output;
  auto fps = run_gvkit("capture --source synthetic: --pattern psp3-f16 --fps -2" + out);
  EXPECT_NE(fps.exit_code, 0);
  EXPECT_TRUE(contains(fps.output, "--fps")) << fps.output;
  EXPECT_FALSE(fs::exists(dir / "x" / "session.json"));  // no failed run leaves a session
}

}  // namespace
}  // namespace gvkit
