// `gvkit reconstruct` on a plain folder of numbered images with a foreign calibration, as a new
// user brings them: what it says when the pattern, the calibration or the projector size is
// missing, when the calibration is of another resolution or a stray image spoils the count, and
// that a failing run leaves the outputs of an earlier one alone.
#include <gtest/gtest.h>

#include <fstream>

#include "gvkit/capture/pattern_set.hpp"
#include "gvkit/core/calibration_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "plain_folder_fixture.hpp"
#include "support/test_support.hpp"

namespace gvkit::capture {
namespace {
using testing::contains;
using testing::run_gvkit;
using testing::TempDir;
namespace fs = std::filesystem;

class CliPlainFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    calibration_ = fixture::rig({128, 104});
    auto patterns = create_pattern_set("mf4-f16-f1");
    ASSERT_TRUE(patterns);
    const SyntheticScene scene = fixture::bump_scene();
    const SyntheticRenderer renderer(calibration_, {});
    const SyntheticFrame frame = renderer.render(scene, (*patterns)->generate({912, 570}), 1);
    images_ = dir_ / "scan";
    fixture::write_numbered(images_, frame.images, "img_", "bmp");
    fs::create_directories(dir_ / "gt");
    ASSERT_TRUE(write_ground_truth_exr(dir_ / "gt" / "frame_000000.exr",
                                       ground_truth_of(frame.truth, scene))
                    .is_ok());
    // scan3d-capture's layout: no device sizes.
    ASSERT_TRUE(
        write_calibration(dir_ / "procam.yml", calibration_, CalibrationFormat::kProcam).is_ok());
  }

  std::string reconstruct(const std::string& extra, const fs::path& out) const {
    return "reconstruct " + images_.string() + " -o " + out.string() + " --no-progress " + extra;
  }

  TempDir dir_;
  fs::path images_;
  Calibration calibration_;
};

TEST_F(CliPlainFolder, MissingPatternListsTheSetsThatFitAndTheOptions) {
  auto r = run_gvkit(reconstruct("", dir_ / "out"));
  ASSERT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.output, images_.string() + ": a folder of 8 fringe images")) << r.output;
  EXPECT_TRUE(contains(r.output, "needs --pattern and --calibration")) << r.output;
  EXPECT_TRUE(contains(r.output, "cannot be inferred")) << r.output;
  for (const char* candidate : {"psp8-f<P>", "mf4-f<P>-f1", "gray5-psp3", "gray4-psp4"})
    EXPECT_TRUE(contains(r.output, candidate)) << candidate << "\n" << r.output;
  EXPECT_TRUE(contains(r.output, "k = 4: psp4-f<P>")) << r.output;
  EXPECT_TRUE(contains(r.output, "SPEC.json")) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "out"));

  auto no_calibration = run_gvkit(reconstruct("--pattern mf4-f16-f1", dir_ / "out"));
  ASSERT_NE(no_calibration.exit_code, 0);
  EXPECT_TRUE(contains(no_calibration.output, "needs --calibration")) << no_calibration.output;
  EXPECT_TRUE(contains(no_calibration.output, "procam")) << no_calibration.output;
}

TEST_F(CliPlainFolder, ForeignCalibrationNeedsTheProjectorSizeThenMatchesTheTruth) {
  const std::string base = "--pattern mf4-f16-f1 --calibration " + (dir_ / "procam.yml").string();
  auto no_size = run_gvkit(reconstruct(base, dir_ / "out"));
  ASSERT_NE(no_size.exit_code, 0);
  EXPECT_TRUE(contains(no_size.output, "procam.yml (procam layout): no projector size"))
      << no_size.output;
  EXPECT_TRUE(contains(no_size.output, "--projector-size")) << no_size.output;

  auto ok = run_gvkit(reconstruct(
      base + " --projector-size 912x570 --ground-truth " + (dir_ / "gt").string(), dir_ / "out"));
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  auto stats = read_json(dir_ / "out" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  const auto& summary = (*stats)["summary"];
  EXPECT_GT(summary["mean_valid_share"].get<double>(), 0.6);
  EXPECT_LT(summary["rms_depth_error_mm"].get<double>(), 1.0) << summary.dump();
  EXPECT_TRUE(contains((*stats)["options"]["calibration_note"].get<std::string>(),
                       "projector 912x570 from --projector-size"));
  EXPECT_TRUE(fs::exists(dir_ / "out" / "frame_000000.exr"));
}

TEST_F(CliPlainFolder, CalibrationOfAnotherResolutionNamesBothFilesAndKeepsEarlierOutputs) {
  // A first good run.
  ASSERT_TRUE(
      write_calibration(dir_ / "calibration.xml", calibration_, CalibrationFormat::kSlStudio)
          .is_ok());
  const fs::path out = dir_ / "out";
  auto first = run_gvkit(reconstruct(
      "--pattern mf4-f16-f1 --calibration " + (dir_ / "calibration.xml").string(), out));
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const auto stats_time = fs::last_write_time(out / "stats.json");

  // The same rig calibrated with the camera at twice the resolution.
  ASSERT_TRUE(
      write_calibration(dir_ / "full.xml", fixture::rig({256, 208}), CalibrationFormat::kSlStudio)
          .is_ok());
  const std::string full = "--pattern mf4-f16-f1 --calibration " + (dir_ / "full.xml").string();
  auto r = run_gvkit(reconstruct(full, out));
  ASSERT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.output, (images_ / "img_1.bmp").string() + " is 128x104")) << r.output;
  EXPECT_TRUE(contains(r.output, "full.xml calibrates a 256x208 camera")) << r.output;
  EXPECT_TRUE(contains(r.output, "--rescale-calibration would scale")) << r.output;
  EXPECT_TRUE(contains(r.output, "by 0.5")) << r.output;
  // Nothing written earlier is lost.
  EXPECT_TRUE(fs::exists(out / "frame_000000.exr"));
  EXPECT_EQ(fs::last_write_time(out / "stats.json"), stats_time);
  auto stats = read_json(out / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["complete"], true);

  auto rescaled = run_gvkit(reconstruct(
      full + " --rescale-calibration --ground-truth " + (dir_ / "gt").string(), dir_ / "out2"));
  ASSERT_EQ(rescaled.exit_code, 0) << rescaled.output;
  auto stats2 = read_json(dir_ / "out2" / "stats.json");
  ASSERT_TRUE(stats2.is_ok());
  EXPECT_LT((*stats2)["summary"]["rms_depth_error_mm"].get<double>(), 1.0);

  // Another aspect ratio (a cropped image) cannot be rescaled.
  ASSERT_TRUE(
      write_calibration(dir_ / "wide.xml", fixture::rig({256, 160}), CalibrationFormat::kSlStudio)
          .is_ok());
  auto wide = run_gvkit(reconstruct(
      "--pattern mf4-f16-f1 --rescale-calibration --calibration " + (dir_ / "wide.xml").string(),
      dir_ / "out3"));
  ASSERT_NE(wide.exit_code, 0);
  EXPECT_TRUE(contains(wide.output, "aspect ratios differ")) << wide.output;
}

TEST_F(CliPlainFolder, AStrayImageIsNamedAndCanBeLeftOut) {
  cv::imwrite((images_ / "white.bmp").string(), cv::Mat(104, 128, CV_8U, cv::Scalar(250)));
  const std::string base = "--pattern mf4-f16-f1 --projector-size 912x570 --calibration " +
                           (dir_ / "procam.yml").string();
  auto r = run_gvkit(reconstruct(base, dir_ / "out"));
  ASSERT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.output, "9 images (img_1.bmp .. white.bmp)")) << r.output;
  EXPECT_TRUE(contains(r.output, "img_#.bmp (8) white.bmp (1)")) << r.output;
  auto ok = run_gvkit(reconstruct(base + " --exclude 'white*'", dir_ / "out"));
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  auto only = run_gvkit(reconstruct(base + " --images 'img_*'", dir_ / "out2"));
  ASSERT_EQ(only.exit_code, 0) << only.output;
}

TEST_F(CliPlainFolder, UnknownCalibrationLayoutListsItsKeys) {
  std::ofstream(dir_ / "odd.yml") << "%YAML:1.0\nfocal: 1000\nbaseline: 200\n";
  auto r = run_gvkit(reconstruct(
      "--pattern mf4-f16-f1 --calibration " + (dir_ / "odd.yml").string(), dir_ / "out"));
  ASSERT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.output,
                       "odd.yml: unknown calibration layout; keys found: focal, "
                       "baseline"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "SLStudio (Kc")) << r.output;
}

}  // namespace
}  // namespace gvkit::capture
