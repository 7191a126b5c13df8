#include <gtest/gtest.h>

#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {

TEST(FacemapCli, MapsAnIctSequenceWithBothMethodsAndCompares) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  testing::TempDir dir;
  const std::string faces = (dir / "faces").string();
  auto r = testing::run_gvkit("facemap ict-sequence " + (data / "ict-facekit").string() + " -o " +
                              faces + " --frames 2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const std::string method : {"eip", "hm"}) {
    r = testing::run_gvkit("facemap map " + faces + " -o " + (dir / method).string() +
                           " --size 64x64 --same-vertices --method " + method);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    auto image = read_geometry_image_exr(dir / method / "frame_000001.exr");
    ASSERT_TRUE(image.is_ok()) << image.status().message();
    EXPECT_EQ(image->size(), cv::Size(64, 64));
    auto stats = read_json(dir / method / "stats.json");
    ASSERT_TRUE(stats.is_ok());
    EXPECT_EQ((*stats)["summary"]["mapped"], 2);
    EXPECT_TRUE((*stats)["summary"].contains("temporal_mse_mean_mm2"));
    EXPECT_TRUE((*stats)["summary"].contains("true_drift_rms_mm"));
    // The same temporal error per unit of surface, and both for frame 0's samples carried to
    // frame 1 (a map without drift): the two frames differ in expression, so none is zero.
    for (const char* key : {"temporal_mse_area_weighted_mm2", "temporal_mse_drift_free_mean_mm2",
                            "temporal_mse_drift_free_area_weighted_mm2"}) {
      ASSERT_TRUE((*stats)["summary"].contains(key)) << key;
      EXPECT_GT((*stats)["summary"][key].get<double>(), 0.0) << key;
    }
    EXPECT_EQ((*stats)["options"]["method"], method);
  }
  // The seed's plain cotangent weights (the reference): recorded, and another map (the ICT mesh
  // has edges that are not locally Delaunay, whose weights the default floors).
  r = testing::run_gvkit("facemap map " + faces + " -o " + (dir / "plain").string() +
                         " --size 64x64 --same-vertices --plain-cotan");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto plain_stats = read_json(dir / "plain" / "stats.json");
  auto eip_stats = read_json(dir / "eip" / "stats.json");
  ASSERT_TRUE(plain_stats.is_ok() && eip_stats.is_ok());
  EXPECT_EQ((*plain_stats)["options"]["plain_cotan"], true);
  EXPECT_EQ((*eip_stats)["options"]["plain_cotan"], false);
  EXPECT_EQ((*plain_stats)["summary"]["flipped_total"], 0);
  auto plain_image = read_geometry_image_exr(dir / "plain" / "frame_000001.exr");
  auto eip_image = read_geometry_image_exr(dir / "eip" / "frame_000001.exr");
  ASSERT_TRUE(plain_image.is_ok() && eip_image.is_ok());
  EXPECT_GT(cv::norm(plain_image->xyz_mm, eip_image->xyz_mm, cv::NORM_INF), 0.0);
  // The multigrid solves (the default from 100K vertices on) give the direct solves' map; each
  // frame records the map's steps' CPU time. (Written with RLE: the same values.)
  r = testing::run_gvkit("facemap map " + faces + " -o " + (dir / "multigrid").string() +
                         " --size 64x64 --same-vertices --solver multigrid --exr-compression rle");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto multigrid_stats = read_json(dir / "multigrid" / "stats.json");
  ASSERT_TRUE(multigrid_stats.is_ok());
  EXPECT_EQ((*multigrid_stats)["options"]["solver"], "multigrid");
  EXPECT_EQ((*eip_stats)["options"]["solver"], "auto");
  EXPECT_EQ((*multigrid_stats)["options"]["exr_compression"], "rle");
  EXPECT_EQ((*eip_stats)["options"]["exr_compression"], "zip");
  EXPECT_GT((*multigrid_stats)["frames"][0]["cpu_ms"]["total"].get<double>(), 0.0);
  EXPECT_EQ((*multigrid_stats)["summary"]["flipped_total"], 0);
  auto multigrid_image = read_geometry_image_exr(dir / "multigrid" / "frame_000001.exr");
  ASSERT_TRUE(multigrid_image.is_ok());
  EXPECT_LT(cv::norm(multigrid_image->xyz_mm, eip_image->xyz_mm, cv::NORM_INF), 1e-3);
  r = testing::run_gvkit("facemap compare " + (dir / "eip").string() + " " + (dir / "hm").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("temporal MSE mean"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("temporal MSE without drift"), std::string::npos) << r.output;
}

TEST(FacemapCli, BadOptionsAndMissingInputFailWithAMessage) {
  testing::TempDir dir;
  auto r = testing::run_gvkit("facemap map " + dir.path().string() + " -o " +
                              (dir / "out").string() + " --size 12");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--size"), std::string::npos) << r.output;
  r = testing::run_gvkit("facemap map " + dir.path().string() + " -o " + (dir / "out").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("no frame_NNNNNN.ply"), std::string::npos) << r.output;
  r = testing::run_gvkit("facemap map " + dir.path().string() + " -o " + (dir / "out").string() +
                         " --method xyz");
  EXPECT_NE(r.exit_code, 0);
  r = testing::run_gvkit("facemap map " + dir.path().string() + " -o " + (dir / "out").string() +
                         " --rim sideways");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--rim must be arclength, angle or flow"), std::string::npos) << r.output;
  r = testing::run_gvkit("facemap map " + dir.path().string() + " -o " + (dir / "out").string() +
                         " --solver lu");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--solver must be auto, direct or multigrid"), std::string::npos)
      << r.output;
  r = testing::run_gvkit("facemap map " + dir.path().string() + " -o " + (dir / "out").string() +
                         " --exr-compression piz");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--exr-compression: EXR compression 'piz'"), std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace gvkit
