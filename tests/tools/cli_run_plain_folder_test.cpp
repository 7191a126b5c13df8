// `gvkit run` on a plain folder of an unseen pattern family, as a user with another rig brings
// it: numbered BMPs of a complementary Gray code + 4-step phase shift with white and black
// references (gvkit synth --plain-folder, 288x224 camera, 1024x640 projector), a procam-layout
// calibration without device sizes. Without --pattern the run stops at once and says what fits;
// with it the chain reaches a .gvid that decodes and, with the player, renders offscreen.
#include <filesystem>

#include <gtest/gtest.h>

#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::contains;
using testing::run_gvkit;
using testing::TempDir;
namespace fs = std::filesystem;

TEST(CliRunPlainFolder, UnseenFamilyWithForeignCalibrationToAPlayedGvid) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  if (!fs::exists("/usr/share/dlib/shape_predictor_68_face_landmarks.dat"))
    GTEST_SKIP() << "dlib model absent (package libdlib-data)";
  TempDir dir;
  const fs::path folder = dir / "their_rig", work = dir / "work";
  auto synth = run_gvkit("synth -o " + folder.string() +
                         " --plain-folder --image-format bmp --calibration-layout procam"
                         " --pattern cgray5-psp4-owbgp --frames 2 --size 288x224"
                         " --projector-size 1024x640 --expressions neutral --no-progress");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  ASSERT_FALSE(fs::exists(folder / "session.json"));
  ASSERT_TRUE(fs::exists(folder / "img_32.bmp"));  // 2 frames x 16 images

  // No pattern: nothing runs, the message lists what fits 16 images and the options to give.
  auto guess = run_gvkit("run " + folder.string() + " -o " + work.string() + " --calibration " +
                         (folder / "calibration.yml").string());
  ASSERT_NE(guess.exit_code, 0);
  EXPECT_TRUE(contains(guess.output, "32 fringe images")) << guess.output;
  EXPECT_TRUE(contains(guess.output, "needs --pattern")) << guess.output;
  // 16 images per frame fit, among others, the complementary Gray code with references.
  EXPECT_TRUE(contains(guess.output, "k = 16: psp16-f<P>")) << guess.output;
  EXPECT_TRUE(contains(guess.output, "cgray5-psp4-owbpg")) << guess.output;
  EXPECT_FALSE(fs::exists(work / "scans" / "frame_000000.exr"));

  std::string run = "run " + folder.string() + " -o " + work.string() +
                    " --pattern cgray5-psp4-owbgp --calibration " +
                    (folder / "calibration.yml").string() +
                    " --projector-size 1024x640 --ground-truth " + (folder / "gt").string() +
                    " --map-size 48x48 --preset fast";
#ifdef GVKIT_WITH_PLAYER
  run += " --render";
#endif
  auto r = run_gvkit(run);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(fs::exists(work / "face.gvid"));
  auto scans = read_json(work / "scans" / "stats.json");
  ASSERT_TRUE(scans.is_ok());
  EXPECT_EQ((*scans)["options"]["pattern"], "cgray5-psp4-owbgp");
  EXPECT_LT((*scans)["summary"]["face_interior_rms_mm"].get<double>(), 0.5) << scans->dump();
  EXPECT_GT((*scans)["summary"]["face_interior_valid_share"].get<double>(), 0.9);
  auto decoded = list_frame_files(work / "decoded", ".exr");
  ASSERT_TRUE(decoded.is_ok());
  EXPECT_EQ(decoded->size(), 2u);
  auto info = run_gvkit("info " + (work / "face.gvid").string());
  EXPECT_EQ(info.exit_code, 0) << info.output;
#ifdef GVKIT_WITH_PLAYER
  EXPECT_TRUE(fs::exists(work / "face.mp4"));
  EXPECT_TRUE(fs::exists(work / "contact.png"));
#endif
}

}  // namespace
}  // namespace gvkit
