// gvkit synth and gvkit reconstruct as a user runs them.
#include <gtest/gtest.h>

#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::run_gvkit;
using testing::TempDir;

using testing::contains;

TEST(CliCapture, SynthThenReconstructWithGroundTruth) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  TempDir dir;
  const std::string session = (dir / "session").string(), scans = (dir / "scans").string();
  auto s = run_gvkit("synth -o " + session +
                     " --frames 2 --size 128x96 --pattern mf3-f16-f1 "
                     "--noise 0.005 --seed 4 --no-progress --ict " +
                     (data / "ict-facekit").string());
  ASSERT_EQ(s.exit_code, 0) << s.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "session" / "gt" / "frame_000001.exr"));
  EXPECT_TRUE(std::filesystem::exists(dir / "session" / "gt" / "frame_000001.landmarks.json"));
  EXPECT_TRUE(std::filesystem::exists(dir / "session" / "frames" / "frame_000001_k5.png"));
  auto r = run_gvkit("reconstruct " + session + " -o " + scans + " --ply --no-progress");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto scan = read_range_scan_exr(dir / "scans" / "frame_000001.exr");
  ASSERT_TRUE(scan) << scan.status().message();
  EXPECT_EQ(scan->size(), cv::Size(128, 96));
  EXPECT_GT(scan->valid_fraction(), 0.05);
  EXPECT_TRUE(std::filesystem::exists(dir / "scans" / "frame_000000.ply"));
  auto stats = read_json(dir / "scans" / "stats.json");
  ASSERT_TRUE(stats);
  ASSERT_EQ((*stats)["frames"].size(), 2u);
  EXPECT_LT((*stats)["frames"][0]["p99_depth_error_mm"].get<double>(), 5.0);
  EXPECT_EQ((*stats)["options"]["pattern"], "mf3-f16-f1");
  EXPECT_TRUE((*stats)["summary"].contains("rms_depth_error_mm"));
}

// A spatially unwrapped pattern set knows each region's phase only up to whole periods; the
// session records the face's depth, so a face 800 mm away is not put one period nearer (the
// 650 mm default prior puts it about 150 mm off).
TEST(CliCapture, SpatialUnwrappingUsesTheSessionsDepthPrior) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  TempDir dir;
  const std::string session = (dir / "session").string();
  auto s = run_gvkit("synth -o " + session +
                     " --frames 1 --size 128x96 --pattern psp3-f16 --distance 800 --no-progress "
                     "--ict " +
                     (data / "ict-facekit").string());
  ASSERT_EQ(s.exit_code, 0) << s.output;
  auto info = read_json(dir / "session" / "session.json");
  ASSERT_TRUE(info);
  EXPECT_EQ((*info)["depth_prior_mm"].get<double>(), 800.0);
  auto r =
      run_gvkit("reconstruct " + session + " -o " + (dir / "scans").string() + " --no-progress");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto stats = read_json(dir / "scans" / "stats.json");
  ASSERT_TRUE(stats);
  EXPECT_EQ((*stats)["options"]["depth_prior_from"], "session");
  EXPECT_LT((*stats)["frames"][0]["median_depth_error_mm"].get<double>(), 2.0);
  // An explicit --depth-prior wins over the session's: 650 mm picks the wrong period here.
  r = run_gvkit("reconstruct " + session + " -o " + (dir / "near").string() +
                " --depth-prior 650 --no-progress");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  stats = read_json(dir / "near" / "stats.json");
  ASSERT_TRUE(stats);
  EXPECT_EQ((*stats)["options"]["depth_prior_from"], "--depth-prior");
  EXPECT_GT((*stats)["frames"][0]["median_depth_error_mm"].get<double>(), 50.0);
}

TEST(CliCapture, BadOptionsFailWithAMessage) {
  TempDir dir;
  auto a = run_gvkit("synth -o " + (dir / "a").string() + " --size 12-by-12");
  EXPECT_NE(a.exit_code, 0);
  EXPECT_TRUE(contains(a.output, "--size")) << a.output;
  auto b = run_gvkit("synth -o " + (dir / "b").string() + " --pattern psp2-f4");
  EXPECT_NE(b.exit_code, 0);
  EXPECT_TRUE(contains(b.output, "psp2-f4")) << b.output;
  auto c = run_gvkit("synth -o " + (dir / "c").string() + " --noise 3");
  EXPECT_NE(c.exit_code, 0);
  EXPECT_TRUE(contains(c.output, "noise")) << c.output;
  auto d = run_gvkit("reconstruct " + dir.path().string() + " -o " + (dir / "d").string());
  EXPECT_NE(d.exit_code, 0);
  EXPECT_TRUE(contains(d.output, "--pattern and --calibration")) << d.output;
  auto help = run_gvkit("reconstruct --help");
  EXPECT_TRUE(contains(help.output, "gray<B>-psp<N>")) << help.output;
}

TEST(CliCapture, ReconstructsAPlainFolderOfSkullImages) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  TempDir dir;
  const auto skull = data / "slstudio-skull-2x3";
  auto r = run_gvkit("reconstruct " + skull.string() + " --pattern mf3-f16-f1 --calibration " +
                     (skull / "calibration.xml").string() + " -o " + (dir / "out").string() +
                     " --no-progress");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto scan = read_range_scan_exr(dir / "out" / "frame_000000.exr");
  ASSERT_TRUE(scan);
  EXPECT_EQ(scan->size(), cv::Size(1688, 1352));
  EXPECT_GT(scan->valid_fraction(), 0.1);
  // The wrong pattern for 6 images: 6 is not a multiple of 4.
  auto bad = run_gvkit("reconstruct " + skull.string() + " --pattern psp4-f16 --calibration " +
                       (skull / "calibration.xml").string() + " -o " + (dir / "bad").string());
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(contains(bad.output, "not a multiple")) << bad.output;
}

TEST(CliCapture, CalibratesSyntheticBoardCaptures) {
  TempDir dir;
  const std::string session = (dir / "board").string(), out = (dir / "cal.yaml").string();
  auto r = run_gvkit("calibrate --synth-board " + session + " --poses 6 --size 320x240 --pattern " +
                     "mf3-f16-f1 " + session + " -o " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "calibrated from 6 captures")) << r.output;
  auto info = run_gvkit("info " + out);
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_TRUE(contains(info.output, "reprojection error")) << info.output;
  auto bad = run_gvkit("calibrate " + session + " -o " + out + " --board 8");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(contains(bad.output, "--board")) << bad.output;
}

}  // namespace
}  // namespace gvkit
