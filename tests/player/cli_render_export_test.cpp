// gvkit render and gvkit export end to end, on a small synthetic geometry video.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/videoio.hpp>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/image_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/mesh_io.hpp"
#include "player_test_data.hpp"
#include "support/test_support.hpp"

namespace gvkit::player {
namespace {

namespace fs = std::filesystem;
using gvkit::testing::run_gvkit;
using gvkit::testing::TempDir;

class CliPlayer : public ::testing::Test {
 protected:
  void SetUp() override { testing::write_face_like_sequence(tmp_ / "seq", 4, 32); }
  std::string seq() const { return (tmp_ / "seq").string(); }
  TempDir tmp_;
};

#ifdef GVKIT_WITH_PLAYER
TEST_F(CliPlayer, RenderWritesPngFramesStatsAndContactSheet) {
  const auto r =
      run_gvkit("render " + seq() + " -o " + (tmp_ / "png").string() +
                " --size 96x64 --frames 1:4 --view orbit --shading normals" + " --contact-sheet " +
                (tmp_ / "sheet.png").string() + " --contact-frames 3 --contact-columns 2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto frames = list_frame_files(tmp_ / "png", ".png");
  ASSERT_TRUE(frames.is_ok());
  ASSERT_EQ(frames->size(), 3u);
  EXPECT_EQ(frames->front().index, 1);
  auto picture = read_image(frames->front().path);
  ASSERT_TRUE(picture.is_ok());
  EXPECT_EQ(picture->size(), cv::Size(96, 64));
  auto sheet = read_image(tmp_ / "sheet.png");
  ASSERT_TRUE(sheet.is_ok());
  EXPECT_EQ(sheet->cols, 2 * 96 + 3 * 2);  // two columns and gutters
  EXPECT_EQ(sheet->rows, 2 * 64 + 3 * 2);
  auto stats = read_json(tmp_ / "png" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["summary"]["rendered"], 3);
  EXPECT_EQ((*stats)["options"]["view"], "orbit");
}

TEST_F(CliPlayer, RenderWritesAnMp4) {
  const fs::path mp4 = tmp_ / "clip.mp4";
  const auto r = run_gvkit("render " + seq() + " -o " + mp4.string() + " --size 64x48");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  cv::VideoCapture capture(mp4.string(), cv::CAP_FFMPEG);
  ASSERT_TRUE(capture.isOpened());
  int n = 0;
  cv::Mat frame;
  while (capture.read(frame)) ++n;
  EXPECT_EQ(n, 4);
  EXPECT_EQ(frame.cols, 0);  // read past the end
  EXPECT_TRUE(fs::exists(tmp_ / "clip.stats.json"));
}

TEST_F(CliPlayer, RenderErrorShadingAgainstAReference) {
  const auto r = run_gvkit("render " + seq() + " --reference " + seq() + " --shading error" +
                           " --contact-sheet " + (tmp_ / "e.png").string() + " --size 64x64");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(tmp_ / "e.png"));
  const auto missing = run_gvkit("render " + seq() + " --shading error --contact-sheet x.png");
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("--reference"), std::string::npos) << missing.output;
}

TEST_F(CliPlayer, RenderReportsACorruptFrameAndWritesTheOthers) {
  fs::resize_file(frame_path(tmp_ / "seq", 2, ".exr"), 100);
  const auto r = run_gvkit("render " + seq() + " -o " + (tmp_ / "png").string() + " --size 64x48");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("1 of 4 frames failed"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("frame_000002.exr"), std::string::npos) << r.output;
  auto frames = list_frame_files(tmp_ / "png", ".png");
  ASSERT_TRUE(frames.is_ok());
  EXPECT_EQ(frames->size(), 3u);
}

TEST_F(CliPlayer, CompareWritesTheSheetTheVideoAndTheFigures) {
  // The "decoded" video: the sequence with a 0.3 mm ripple of 8 pixels along x on z.
  ASSERT_TRUE(ensure_directory(tmp_ / "rippled").is_ok());
  for (int f = 0; f < 4; ++f) {
    GeometryImage image = testing::make_face_like_image(32, f);
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x)
        image.xyz_mm.at<cv::Vec3f>(y, x)[2] += static_cast<float>(0.3 * std::sin(x * M_PI / 4));
    ASSERT_TRUE(write_geometry_image_exr(frame_path(tmp_ / "rippled", f, ".exr"), image).is_ok());
  }
  const std::string gvid = (tmp_ / "rippled").string();
  const fs::path mp4 = tmp_ / "c.mp4", png = tmp_ / "c.png";
  const auto r = run_gvkit("compare " + seq() + " " + gvid + " -o " + mp4.string() +
                           " --contact-sheet " + png.string() + " --size 96x64 --contact-frames 2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("normal error mean"), std::string::npos) << r.output;
  auto sheet = read_image(png);
  ASSERT_TRUE(sheet.is_ok());
  EXPECT_EQ(sheet->cols, 3 * 96 + 4 * 2);  // input | decoded | heat map
  EXPECT_EQ(sheet->rows, 2 * 64 + 3 * 2);  // two frames
  cv::VideoCapture capture(mp4.string(), cv::CAP_FFMPEG);
  ASSERT_TRUE(capture.isOpened());
  cv::Mat frame;
  ASSERT_TRUE(capture.read(frame));
  EXPECT_EQ(frame.size(), cv::Size(3 * 96, 64));
  auto stats = read_json(tmp_ / "c.stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["frames"].size(), 4u);
  EXPECT_GT((*stats)["summary"]["normal_p95_deg"].get<double>(), 0.0);
  EXPECT_GT((*stats)["summary"]["hausdorff_mm"].get<double>(), 0.0);
  EXPECT_LE((*stats)["summary"]["hausdorff_mm"].get<double>(),
            (*stats)["summary"]["max_mm"].get<double>() + 1e-6);

  // A video against itself: nothing to see; figures only, no picture.
  const auto same = run_gvkit("compare " + seq() + " " + seq() + " --stats " +
                              (tmp_ / "same.json").string() + " --heat distance");
  ASSERT_EQ(same.exit_code, 0) << same.output;
  auto zero = read_json(tmp_ / "same.json");
  ASSERT_TRUE(zero.is_ok());
  EXPECT_EQ((*zero)["summary"]["normal_max_deg"].get<double>(), 0.0);
  EXPECT_EQ((*zero)["summary"]["hausdorff_mm"].get<double>(), 0.0);
}

TEST_F(CliPlayer, CompareRejectsMismatchesAndBadOptions) {
  testing::write_face_like_sequence(tmp_ / "short", 2, 32);
  const auto count = run_gvkit("compare " + seq() + " " + (tmp_ / "short").string());
  EXPECT_NE(count.exit_code, 0);
  EXPECT_NE(count.output.find("2 frames, the reference"), std::string::npos) << count.output;
  testing::write_face_like_sequence(tmp_ / "big", 4, 40);
  const auto size = run_gvkit("compare " + seq() + " " + (tmp_ / "big").string());
  EXPECT_NE(size.exit_code, 0);
  EXPECT_NE(size.output.find("40x40"), std::string::npos) << size.output;
  // Each message names what is wrong.
  const std::pair<const char*, const char*> bad_options[] = {{"--heat colour", "colour"},
                                                             {"--normal-scale 9", "normal scale"},
                                                             {"--hausdorff-window 0", "window"},
                                                             {"--normal-max 0", "--normal-max"},
                                                             {"--pan 1", "--pan"}};
  for (const auto& [bad, named] : bad_options) {
    const auto r = run_gvkit("compare " + seq() + " " + seq() + " " + bad);
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_NE(r.output.find(named), std::string::npos) << bad << ": " << r.output;
  }
}

// --mesh-stride auto (the default) picks the stride from the picture size and records it.
TEST_F(CliPlayer, RenderChoosesTheMeshStrideForThePictureSize) {
  for (const auto& [size, stride] : {std::pair{"24x24", 2}, std::pair{"256x256", 1}}) {
    const fs::path out = tmp_ / (std::string("auto_") + size);
    const auto r =
        run_gvkit("render " + seq() + " -o " + out.string() + " --size " + size + " --frames 1");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    auto stats = read_json(out / "stats.json");
    ASSERT_TRUE(stats.is_ok());
    EXPECT_EQ((*stats)["options"]["mesh_stride"], "auto");
    EXPECT_EQ((*stats)["options"]["mesh_stride_used"], stride) << size;
  }
  const auto fixed = run_gvkit("render " + seq() + " -o " + (tmp_ / "fixed").string() +
                               " --size 24x24 --frames 1 --mesh-stride 1");
  ASSERT_EQ(fixed.exit_code, 0) << fixed.output;
  EXPECT_EQ((*read_json(tmp_ / "fixed" / "stats.json"))["options"]["mesh_stride_used"], 1);
}

TEST_F(CliPlayer, RenderRejectsBadOptions) {
  for (const char* bad : {"--size 0x3", "--size big", "--view top", "--shading glossy",
                          "--frames 3:1", "--frames 9:", "--size 63x48 -o x.mp4",
                          "--mesh-stride fine", "--mesh-stride 0", "--mesh-stride 2x"}) {
    const auto r =
        run_gvkit("render " + seq() + " --contact-sheet " + (tmp_ / "s.png").string() + " " + bad);
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_NE(r.output.find("error"), std::string::npos) << bad << ": " << r.output;
  }
}
#endif

TEST_F(CliPlayer, ExportPlyObjAndExr) {
  auto ply = run_gvkit("export " + seq() + " --format ply -o " + (tmp_ / "ply").string() +
                       " --frames 0:2");
  ASSERT_EQ(ply.exit_code, 0) << ply.output;
  auto mesh = read_mesh(frame_path(tmp_ / "ply", 1, ".ply"));
  ASSERT_TRUE(mesh.is_ok()) << mesh.status().message();
  const GeometryImage source = testing::make_face_like_image(32, 1);
  EXPECT_EQ(mesh->n_vertices(), static_cast<size_t>(cv::countNonZero(source.domain_mask)));
  EXPECT_GT(mesh->n_faces(), mesh->n_vertices());
  EXPECT_FALSE(fs::exists(frame_path(tmp_ / "ply", 2, ".ply")));

  auto obj =
      run_gvkit("export " + seq() + " --format obj -o " + (tmp_ / "obj").string() + " --frames 3");
  ASSERT_EQ(obj.exit_code, 0) << obj.output;
  EXPECT_TRUE(read_mesh(frame_path(tmp_ / "obj", 3, ".obj")).is_ok());

  auto exr = run_gvkit("export " + seq() + " --format exr -o " + (tmp_ / "exr").string());
  ASSERT_EQ(exr.exit_code, 0) << exr.output;
  auto back = read_geometry_image_exr(frame_path(tmp_ / "exr", 2, ".exr"));
  ASSERT_TRUE(back.is_ok());
  const GeometryImage expected = testing::make_face_like_image(32, 2);
  EXPECT_EQ(cv::norm(back->xyz_mm, expected.xyz_mm, cv::NORM_INF, expected.domain_mask), 0.0);
  auto stats = read_json(tmp_ / "exr" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["summary"]["written"], 4);
}

// Frames are meshed and written on worker threads: the files are the same with one or several.
TEST_F(CliPlayer, ExportFilesDoNotDependOnThreads) {
  for (const char* threads : {"1", "3"}) {
    const auto r =
        run_gvkit("export " + seq() + " --format ply -o " +
                  (tmp_ / (std::string("t") + threads)).string() + " --threads " + threads);
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  for (int i = 0; i < 4; ++i) {
    const auto a = read_file(frame_path(tmp_ / "t1", i, ".ply")),
               b = read_file(frame_path(tmp_ / "t3", i, ".ply"));
    ASSERT_TRUE(a.is_ok() && b.is_ok());
    EXPECT_EQ(a.value(), b.value()) << i;
  }
  auto stats = read_json(tmp_ / "t3" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["options"]["threads"], 3);
  ASSERT_EQ((*stats)["frames"].size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ((*stats)["frames"][i]["index"], i);  // in frame order
  EXPECT_NE(
      run_gvkit("export " + seq() + " -o " + (tmp_ / "x").string() + " --threads -1").exit_code, 0);
}

TEST_F(CliPlayer, ExportRejectsBadFormatAndMissingInput) {
  auto r = run_gvkit("export " + seq() + " --format stl -o " + (tmp_ / "x").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("ply, obj or exr"), std::string::npos) << r.output;
  r = run_gvkit("export " + (tmp_ / "nothing").string() + " -o " + (tmp_ / "x").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("nothing"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace gvkit::player
