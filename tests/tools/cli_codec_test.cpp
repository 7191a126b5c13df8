// `gvkit encode`, `gvkit decode` and `gvkit info` on .gvid streams, as a user runs them.
#include <fstream>

#include <gtest/gtest.h>

#include "geometry_video_material.hpp"
#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/exr_io.hpp"
#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::run_gvkit;
using testing::TempDir;

using testing::contains;

void write_frames(const std::filesystem::path& dir, int frames) {
  testing::GeometryVideoOptions o;
  o.size = 32;
  o.frames = frames;
  ASSERT_TRUE(ensure_directory(dir).is_ok());
  const auto video = testing::make_analytic_video(o);
  for (size_t i = 0; i < video.size(); ++i)
    ASSERT_TRUE(write_geometry_image_exr(frame_path(dir, static_cast<int64_t>(i), ".exr"), video[i])
                    .is_ok());
}

TEST(CliCodec, EncodeInfoDecodeLossless) {
  TempDir dir;
  write_frames(dir / "in", 2);
  const std::string gvid = (dir / "v.gvid").string();
  auto enc =
      run_gvkit("encode " + (dir / "in").string() + " -o " + gvid + " --lossless --preset fast");
  ASSERT_EQ(enc.exit_code, 0) << enc.output;
  EXPECT_TRUE(contains(enc.output, "2 frames 32x32")) << enc.output;
  auto stats = read_json(gvid + ".stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["options"]["lossless"], true);
  EXPECT_EQ((*stats)["frames"].size(), 2u);

  auto info = run_gvkit("info " + gvid);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_TRUE(contains(info.output, ".gvid geometry video"));
  EXPECT_TRUE(contains(info.output, "32x32, 16-bit xyz"));
  EXPECT_TRUE(contains(info.output, "frames          2"));
  EXPECT_TRUE(contains(info.output, "bits/vertex"));

  auto dec = run_gvkit("decode " + gvid + " -o " + (dir / "out").string());
  ASSERT_EQ(dec.exit_code, 0) << dec.output;
  for (int f = 0; f < 2; ++f) {
    auto a = read_geometry_image_exr(frame_path(dir / "in", f, ".exr"));
    auto b = read_geometry_image_exr(frame_path(dir / "out", f, ".exr"));
    ASSERT_TRUE(a.is_ok() && b.is_ok());
    double worst = 0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x)
        if (a->domain_mask.at<uint8_t>(y, x))
          worst = std::max(worst,
                           cv::norm(a->xyz_mm.at<cv::Vec3f>(y, x) - b->xyz_mm.at<cv::Vec3f>(y, x)));
    EXPECT_LT(worst, 0.01);  // 16-bit quantization of a ~300 mm box: ~0.005 mm steps
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "stats.json"));
}

TEST(CliCodec, EncodeAndDecodeReportTheSurfaceError) {
  TempDir dir;
  write_frames(dir / "in", 3);
  const std::string gvid = (dir / "v.gvid").string();
  auto enc =
      run_gvkit("encode " + (dir / "in").string() + " -o " + gvid + " --qp 12 --preset fast");
  ASSERT_EQ(enc.exit_code, 0) << enc.output;
  EXPECT_TRUE(contains(enc.output, "normal error mean")) << enc.output;
  EXPECT_TRUE(contains(enc.output, "Hausdorff")) << enc.output;
  auto stats = read_json(gvid + ".stats.json");
  ASSERT_TRUE(stats.is_ok());
  const nlohmann::json& summary = (*stats)["summary"];
  for (const char* key : {"normal_mean_deg", "normal_p95_deg", "normal_max_deg", "hausdorff_mm",
                          "outline_hausdorff_mm", "surface_mean_mm"})
    EXPECT_TRUE(summary.contains(key)) << key;
  EXPECT_GT(summary["normal_p95_deg"].get<double>(), 0.0);
  EXPECT_GE(summary["normal_max_deg"].get<double>(), summary["normal_p95_deg"].get<double>());
  EXPECT_TRUE((*stats)["frames"][2].contains("normal_p95_deg"));

  // The decoder measures the same frames against the same input: the same figures.
  auto dec = run_gvkit("decode " + gvid + " -o " + (dir / "out").string() + " --reference " +
                       (dir / "in").string());
  ASSERT_EQ(dec.exit_code, 0) << dec.output;
  EXPECT_TRUE(contains(dec.output, "normal error mean")) << dec.output;
  auto decoded = read_json(dir / "out" / "stats.json");
  ASSERT_TRUE(decoded.is_ok());
  for (const char* key : {"normal_p95_deg", "hausdorff_mm", "max_mm"})
    EXPECT_NEAR((*decoded)["summary"][key].get<double>(), summary[key].get<double>(), 1e-9) << key;

  // A reference that does not match the stream is named.
  write_frames(dir / "two", 2);
  auto bad = run_gvkit("decode " + gvid + " -o " + (dir / "out2").string() + " --reference " +
                       (dir / "two").string());
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(contains(bad.output, "two: 2 frame_NNNNNN.exr files for 3 frames")) << bad.output;
}

TEST(CliCodec, BFramesAreOptionsInfoShowsTheTypesAndDecodeWritesDisplayOrder) {
  TempDir dir;
  write_frames(dir / "in", 5);
  const std::string gvid = (dir / "v.gvid").string();
  auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                       " --lossless --preset fast --bframes 2 --b-qp-offset 3");
  ASSERT_EQ(enc.exit_code, 0) << enc.output;
  auto stats = read_json(gvid + ".stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["options"]["bframes"], 2);
  EXPECT_EQ((*stats)["options"]["b_qp_offset"], 3);
  ASSERT_EQ((*stats)["frames"].size(), 5u);
  // I B B P, then a last frame without a following anchor: P.
  const char* types[] = {"I", "B", "B", "P", "P"};
  for (int f = 0; f < 5; ++f) EXPECT_EQ((*stats)["frames"][f]["type"], types[f]) << f;
  auto info = run_gvkit("info " + gvid);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_TRUE(contains(info.output, "frame types     1 I, 2 P, 2 B")) << info.output;
  EXPECT_TRUE(contains(info.output, "B  ")) << info.output;
  auto dec = run_gvkit("decode " + gvid + " -o " + (dir / "out").string());
  ASSERT_EQ(dec.exit_code, 0) << dec.output;
  for (int f = 0; f < 5; ++f) {
    auto a = read_geometry_image_exr(frame_path(dir / "in", f, ".exr"));
    auto b = read_geometry_image_exr(frame_path(dir / "out", f, ".exr"));
    ASSERT_TRUE(a.is_ok() && b.is_ok());
    double worst = 0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x)
        if (a->domain_mask.at<uint8_t>(y, x))
          worst = std::max(worst,
                           cv::norm(a->xyz_mm.at<cv::Vec3f>(y, x) - b->xyz_mm.at<cv::Vec3f>(y, x)));
    EXPECT_LT(worst, 0.01) << "frame " << f;  // lossless: the frame itself, in display order
  }
  auto bad = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid + " --bframes 4");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(contains(bad.output, "B frames 4 out of range")) << bad.output;
}

TEST(CliCodec, CrossPlaneIsAnOptionInfoShowsItAndTheStreamDecodes) {
  TempDir dir;
  write_frames(dir / "in", 3);
  const std::string gvid = (dir / "v.gvid").string();
  auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                       " --qp 0 --preset fast --no-cross-plane-contexts --no-deblock "
                       "--no-temporal-contexts --no-compact-segments --no-compact-packets "
                       "--no-merge --no-td16 --no-quadratic-intra --resolution full");
  ASSERT_EQ(enc.exit_code, 0) << enc.output;
  auto stats = read_json(gvid + ".stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["options"]["cross_plane"], true);
  EXPECT_EQ((*stats)["options"]["cross_plane_contexts"], false);
  auto bytes = read_file(gvid);
  ASSERT_TRUE(bytes.is_ok());
  EXPECT_EQ(static_cast<uint8_t>((*bytes)[5]), 6);  // version 1.6
  auto info = run_gvkit("info " + gvid);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_TRUE(contains(info.output, "(packet 0)  cross-plane")) << info.output;
  auto dec = run_gvkit("decode " + gvid + " -o " + (dir / "out").string());
  ASSERT_EQ(dec.exit_code, 0) << dec.output;
  // --no-cross-plane: no cross-plane frames; without the other 1.6 tools too, version 1.5.
  auto plain = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                         " --qp 0 --preset fast --no-cross-plane --refs 1 --max-transform 4"
                         " --no-cross-plane-contexts --no-deblock --no-temporal-contexts "
                         "--no-compact-segments --no-compact-packets --no-merge --no-td16 "
                         "--no-quadratic-intra --resolution full");
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  auto plain_info = run_gvkit("info " + gvid);
  ASSERT_EQ(plain_info.exit_code, 0) << plain_info.output;
  EXPECT_FALSE(contains(plain_info.output, "cross-plane")) << plain_info.output;
  auto plain_bytes = read_file(gvid);
  ASSERT_TRUE(plain_bytes.is_ok());
  EXPECT_EQ(static_cast<uint8_t>((*plain_bytes)[5]), 5);
}

// RDO quantization is an encoder option (no syntax): on by default, recorded in the stats, and
// both streams decode.
TEST(CliCodec, RdoQuantizationIsAnOptionAndBothStreamsDecode) {
  TempDir dir;
  write_frames(dir / "in", 3);
  std::string bytes[2];
  for (const bool on : {false, true}) {
    const std::string gvid = (dir / (on ? "on.gvid" : "off.gvid")).string();
    auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid + " --qp 6" +
                         (on ? "" : " --no-rdoq"));
    ASSERT_EQ(enc.exit_code, 0) << enc.output;
    auto stats = read_json(gvid + ".stats.json");
    ASSERT_TRUE(stats.is_ok());
    EXPECT_EQ((*stats)["options"]["rdoq"], on);
    auto dec = run_gvkit("decode " + gvid + " -o " + (dir / (on ? "on" : "off")).string());
    ASSERT_EQ(dec.exit_code, 0) << dec.output;
    auto read = read_file(gvid);
    ASSERT_TRUE(read.is_ok());
    bytes[on] = *read;
  }
  EXPECT_NE(bytes[1], bytes[0]);  // the option reaches the encoder
}

// The deblocking filter (format 1.8): on by default, in the stats and in `gvkit info`;
// --no-deblock writes a version 1.7 stream; both decode.
TEST(CliCodec, DeblockingIsAnOptionInfoShowsItAndBothStreamsDecode) {
  TempDir dir;
  write_frames(dir / "in", 3);
  for (const bool on : {true, false}) {
    const std::string gvid = (dir / (on ? "on.gvid" : "off.gvid")).string();
    auto enc = run_gvkit(
        "encode " + (dir / "in").string() + " -o " + gvid +
        " --qp 12 --no-temporal-contexts --no-compact-segments "
        "--no-compact-packets --no-merge --no-td16 --no-quadratic-intra --resolution full" +
        (on ? "" : " --no-deblock"));
    ASSERT_EQ(enc.exit_code, 0) << enc.output;
    auto stats = read_json(gvid + ".stats.json");
    ASSERT_TRUE(stats.is_ok());
    EXPECT_EQ((*stats)["options"]["deblocking"], on);
    auto bytes = read_file(gvid);
    ASSERT_TRUE(bytes.is_ok());
    EXPECT_EQ(static_cast<uint8_t>((*bytes)[5]), on ? 8 : 7);
    auto info = run_gvkit("info " + gvid);
    ASSERT_EQ(info.exit_code, 0) << info.output;
    EXPECT_EQ(contains(info.output, "  deblocking"), on) << info.output;
    auto dec = run_gvkit("decode " + gvid + " -o " + (dir / (on ? "on" : "off")).string());
    ASSERT_EQ(dec.exit_code, 0) << dec.output;
  }
}

// The fast preset's RDO in I frames: on by default, in the stats; --no-intra-rdo reaches the
// encoder (another stream of the same version); both decode.
TEST(CliCodec, IntraRdoIsAnOptionInTheStatsAndBothStreamsDecode) {
  TempDir dir;
  write_frames(dir / "in", 2);
  std::string bytes[2];
  for (const bool on : {true, false}) {
    const std::string gvid = (dir / (on ? "on.gvid" : "off.gvid")).string();
    auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                         " --qp 6 --preset fast --intra-only" + (on ? "" : " --no-intra-rdo"));
    ASSERT_EQ(enc.exit_code, 0) << enc.output;
    auto stats = read_json(gvid + ".stats.json");
    ASSERT_TRUE(stats.is_ok());
    EXPECT_EQ((*stats)["options"]["intra_rdo"], on);
    auto read = read_file(gvid);
    ASSERT_TRUE(read.is_ok());
    bytes[on] = *read;
    auto dec = run_gvkit("decode " + gvid + " -o " + (dir / (on ? "on" : "off")).string());
    ASSERT_EQ(dec.exit_code, 0) << dec.output;
  }
  EXPECT_NE(bytes[1], bytes[0]);
  EXPECT_EQ(bytes[1][5], bytes[0][5]);  // the same format version
}

// Merge (format 1.11), TD16 (1.12), quadratic intra (1.13) and half resolution (1.14): on by
// default, in the stats; with --resolution full a version 1.13 stream, with --no-quadratic-intra
// as well 1.12, with --no-td16 as well 1.11, with --no-merge as well 1.10; all decode.
TEST(CliCodec, MergeTd16QuadraticIntraAndResolutionAreOptionsInTheStatsAndEveryStreamDecodes) {
  TempDir dir;
  write_frames(dir / "in", 4);
  const std::string off[5] = {"", " --resolution full", " --resolution full --no-quadratic-intra",
                              " --resolution full --no-quadratic-intra --no-td16",
                              " --resolution full --no-quadratic-intra --no-td16 --no-merge"};
  for (int k = 0; k < 5; ++k) {
    const int version = 14 - k;
    const std::string gvid = (dir / ("v" + std::to_string(version) + ".gvid")).string();
    auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                         " --qp 12 --bframes 0" + off[k]);
    ASSERT_EQ(enc.exit_code, 0) << enc.output;
    auto stats = read_json(gvid + ".stats.json");
    ASSERT_TRUE(stats.is_ok());
    EXPECT_EQ((*stats)["options"]["resolution"], version >= 14 ? "auto" : "full");
    EXPECT_EQ((*stats)["options"]["quadratic_intra"], version >= 13);
    EXPECT_EQ((*stats)["options"]["td16"], version >= 12);
    EXPECT_EQ((*stats)["options"]["merge"], version >= 11);
    auto bytes = read_file(gvid);
    ASSERT_TRUE(bytes.is_ok());
    EXPECT_EQ(static_cast<uint8_t>((*bytes)[5]), version);
    auto dec =
        run_gvkit("decode " + gvid + " -o " + (dir / ("v" + std::to_string(version))).string());
    ASSERT_EQ(dec.exit_code, 0) << dec.output;
  }
  // --resolution half: every frame at half resolution, shown by `gvkit info`; it decodes.
  const std::string half = (dir / "half.gvid").string();
  auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + half + " --resolution half");
  ASSERT_EQ(enc.exit_code, 0) << enc.output;
  const auto info = run_gvkit("info " + half);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  size_t shown = 0;
  for (size_t at = info.output.find("half-resolution"); at != std::string::npos;
       at = info.output.find("half-resolution", at + 1))
    ++shown;
  EXPECT_EQ(shown, 4u) << info.output;
  EXPECT_EQ(run_gvkit("decode " + half + " -o " + (dir / "half").string()).exit_code, 0);
  const auto bad = run_gvkit("encode " + (dir / "in").string() + " -o " +
                             (dir / "bad.gvid").string() + " --resolution quarter");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("resolution 'quarter' unknown"), std::string::npos) << bad.output;
}

// Compact packets (format 1.10): on by default, in the stats and in `gvkit info` on every frame;
// --no-compact-packets writes a version 1.9 stream of larger packets; both decode to the same
// frames.
TEST(CliCodec, CompactPacketsAreAnOptionInfoShowsThemAndBothStreamsDecode) {
  TempDir dir;
  write_frames(dir / "in", 3);
  std::string decoded[2];
  int64_t sizes[2] = {0, 0};
  for (const bool on : {true, false}) {
    const std::string gvid = (dir / (on ? "on.gvid" : "off.gvid")).string();
    auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                         " --qp 12 --no-merge --no-td16 --no-quadratic-intra --resolution full" +
                         (on ? "" : " --no-compact-packets"));
    ASSERT_EQ(enc.exit_code, 0) << enc.output;
    auto stats = read_json(gvid + ".stats.json");
    ASSERT_TRUE(stats.is_ok());
    EXPECT_EQ((*stats)["options"]["compact_packets"], on);
    auto bytes = read_file(gvid);
    ASSERT_TRUE(bytes.is_ok());
    EXPECT_EQ(static_cast<uint8_t>((*bytes)[5]), on ? 10 : 9);
    sizes[on] = static_cast<int64_t>(bytes->size());
    auto info = run_gvkit("info " + gvid);
    ASSERT_EQ(info.exit_code, 0) << info.output;
    EXPECT_EQ(contains(info.output, "deblocking  compact-packet"), on) << info.output;
    const auto out = dir / (on ? "on" : "off");
    auto dec = run_gvkit("decode " + gvid + " -o " + out.string());
    ASSERT_EQ(dec.exit_code, 0) << dec.output;
    auto frame = read_file(frame_path(out, 2, ".exr"));
    ASSERT_TRUE(frame.is_ok());
    decoded[on] = *frame;
  }
  EXPECT_LE(sizes[1] + 3 * 9, sizes[0]);  // at least 9 bytes a frame
  EXPECT_TRUE(decoded[1] == decoded[0]);
}

// Temporal contexts (format 1.9): on by default, in the stats and in `gvkit info` on P and B
// frames; --no-temporal-contexts writes a version 1.8 stream; both decode.
TEST(CliCodec, TemporalContextsAreAnOptionInfoShowsThemAndBothStreamsDecode) {
  TempDir dir;
  write_frames(dir / "in", 3);
  for (const bool on : {true, false}) {
    const std::string gvid = (dir / (on ? "on.gvid" : "off.gvid")).string();
    auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                         " --qp 12 --no-compact-packets --no-merge --no-td16 --no-quadratic-intra "
                         "--resolution full" +
                         (on ? "" : " --no-temporal-contexts --no-compact-segments"));
    ASSERT_EQ(enc.exit_code, 0) << enc.output;
    auto stats = read_json(gvid + ".stats.json");
    ASSERT_TRUE(stats.is_ok());
    EXPECT_EQ((*stats)["options"]["temporal_contexts"], on);
    auto bytes = read_file(gvid);
    ASSERT_TRUE(bytes.is_ok());
    EXPECT_EQ(static_cast<uint8_t>((*bytes)[5]), on ? 9 : 8);
    auto info = run_gvkit("info " + gvid);
    ASSERT_EQ(info.exit_code, 0) << info.output;
    EXPECT_EQ(contains(info.output, "  temporal-contexts"), on) << info.output;
    auto dec = run_gvkit("decode " + gvid + " -o " + (dir / (on ? "on" : "off")).string());
    ASSERT_EQ(dec.exit_code, 0) << dec.output;
  }
}

TEST(CliCodec, CrossPlaneContextsAreAnOptionInfoShowsThemAndTheStreamDecodes) {
  TempDir dir;
  write_frames(dir / "in", 3);
  const std::string gvid = (dir / "v.gvid").string();
  auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                       " --qp 0 --preset fast --no-deblock --no-temporal-contexts "
                       "--no-compact-segments --no-compact-packets --no-merge --no-td16 "
                       "--no-quadratic-intra --resolution full");  // on by default
  ASSERT_EQ(enc.exit_code, 0) << enc.output;
  auto stats = read_json(gvid + ".stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["options"]["cross_plane_contexts"], true);
  auto bytes = read_file(gvid);
  ASSERT_TRUE(bytes.is_ok());
  EXPECT_EQ(static_cast<uint8_t>((*bytes)[5]), 7);  // version 1.7
  auto info = run_gvkit("info " + gvid);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_TRUE(contains(info.output, "(packet 0)  cross-plane  cross-plane-contexts"))
      << info.output;
  auto dec = run_gvkit("decode " + gvid + " -o " + (dir / "out").string());
  ASSERT_EQ(dec.exit_code, 0) << dec.output;
  // --no-cross-plane-contexts: version 1.6, no frame with the tool.
  auto off = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                       " --qp 0 --preset fast --no-cross-plane-contexts --no-deblock "
                       "--no-temporal-contexts --no-compact-segments --no-compact-packets "
                       "--no-merge --no-td16 --no-quadratic-intra --resolution full");
  ASSERT_EQ(off.exit_code, 0) << off.output;
  auto off_info = run_gvkit("info " + gvid);
  ASSERT_EQ(off_info.exit_code, 0) << off_info.output;
  EXPECT_FALSE(contains(off_info.output, "cross-plane-contexts")) << off_info.output;
  auto off_bytes = read_file(gvid);
  ASSERT_TRUE(off_bytes.is_ok());
  EXPECT_EQ(static_cast<uint8_t>((*off_bytes)[5]), 6);
}

TEST(CliCodec, PartitionsAreAnOptionInfoShowsThemAndTheStreamDecodes) {
  TempDir dir;
  write_frames(dir / "in", 3);
  const std::string gvid = (dir / "v.gvid").string();
  auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                       " --qp 0 --preset slow --bframes 0 --partitions --no-deblock "
                       "--no-temporal-contexts --no-compact-segments --no-compact-packets "
                       "--no-merge --no-td16 --no-quadratic-intra --resolution full");
  ASSERT_EQ(enc.exit_code, 0) << enc.output;
  auto stats = read_json(gvid + ".stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["options"]["partitions"], true);
  auto bytes = read_file(gvid);
  ASSERT_TRUE(bytes.is_ok());
  EXPECT_EQ(static_cast<uint8_t>((*bytes)[5]), 7);  // version 1.7
  auto info = run_gvkit("info " + gvid);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_TRUE(contains(info.output, "P ")) << info.output;
  EXPECT_TRUE(contains(info.output, "  partitions")) << info.output;
  auto dec = run_gvkit("decode " + gvid + " -o " + (dir / "out").string());
  ASSERT_EQ(dec.exit_code, 0) << dec.output;
  // On by default in the slow preset: the same stream.
  auto defaults = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                            " --qp 0 --preset slow --bframes 0 --no-deblock --no-temporal-contexts "
                            "--no-compact-segments --no-compact-packets --no-merge --no-td16 "
                            "--no-quadratic-intra --resolution full");
  ASSERT_EQ(defaults.exit_code, 0) << defaults.output;
  auto default_bytes = read_file(gvid);
  ASSERT_TRUE(default_bytes.is_ok());
  EXPECT_TRUE(*default_bytes == *bytes);
  // --no-partitions (and no cross-plane contexts): version 1.6, no partition frames; the fast
  // preset codes 16x16 only.
  for (const char* args : {" --preset slow --no-partitions", " --preset fast --partitions"}) {
    auto plain = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                           " --qp 0 --bframes 0 --no-cross-plane-contexts --no-deblock "
                           "--no-temporal-contexts --no-compact-segments --no-compact-packets "
                           "--no-merge --no-td16 --no-quadratic-intra --resolution full" +
                           args);
    ASSERT_EQ(plain.exit_code, 0) << plain.output;
    auto plain_info = run_gvkit("info " + gvid);
    ASSERT_EQ(plain_info.exit_code, 0) << plain_info.output;
    EXPECT_FALSE(contains(plain_info.output, "partitions")) << args << plain_info.output;
    auto plain_bytes = read_file(gvid);
    ASSERT_TRUE(plain_bytes.is_ok());
    EXPECT_EQ(static_cast<uint8_t>((*plain_bytes)[5]), 6) << args;
  }
}

TEST(CliCodec, DecodeOfADamagedStreamWritesTheGoodFramesAndFails) {
  TempDir dir;
  write_frames(dir / "in", 3);
  const std::string gvid = (dir / "v.gvid").string();
  auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                       " --intra-only --qp 0 --preset fast");
  ASSERT_EQ(enc.exit_code, 0) << enc.output;
  auto bytes = read_file(gvid);
  ASSERT_TRUE(bytes.is_ok());
  std::string bad = *bytes;
  bad.resize(bad.size() - 84);   // drops the index (72 bytes) and the trailer (12)
  bad[bad.size() - 10] ^= 0x20;  // damages the last frame's payload
  ASSERT_TRUE(write_file_atomically(gvid, bad).is_ok());
  auto info = run_gvkit("info " + gvid);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_TRUE(contains(info.output, "found by a scan")) << info.output;
  auto dec = run_gvkit("decode " + gvid + " -o " + (dir / "out").string());
  EXPECT_NE(dec.exit_code, 0);
  EXPECT_TRUE(contains(dec.output, "frame 2: payload CRC mismatch")) << dec.output;
  EXPECT_FALSE(std::filesystem::exists(frame_path(dir / "out", 2, ".exr")));
  EXPECT_TRUE(std::filesystem::exists(frame_path(dir / "out", 0, ".exr")));
  EXPECT_TRUE(std::filesystem::exists(frame_path(dir / "out", 1, ".exr")));
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "stats.json"));
}

TEST(CliCodec, MaxErrorModeBoundsEveryFrameAndTheInterToolsAreOptions) {
  TempDir dir;
  write_frames(dir / "in", 3);
  const std::string gvid = (dir / "v.gvid").string();
  auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                       " --max-error-mm 0.05 --gop 3 --value-prediction affine --threads 2 "
                       "--shared-motion "
                       "--preset fast");
  ASSERT_EQ(enc.exit_code, 0) << enc.output;
  auto stats = read_json(gvid + ".stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["options"]["max_error_mm"], 0.05);
  EXPECT_EQ((*stats)["options"]["value_prediction"], "affine");
  EXPECT_EQ((*stats)["options"]["threads"], 2);
  EXPECT_EQ((*stats)["options"]["shared_motion"], true);
  EXPECT_EQ((*stats)["options"]["inter_decimation"], true);
  EXPECT_LE((*stats)["summary"]["max_mm"].get<double>(), 0.05);
  for (const auto& f : (*stats)["frames"]) EXPECT_LE(f["max_mm"].get<double>(), 0.05);
  auto dec = run_gvkit("decode " + gvid + " -o " + (dir / "out").string());
  ASSERT_EQ(dec.exit_code, 0) << dec.output;

  auto rate = run_gvkit("-v encode " + (dir / "in").string() + " -o " + gvid +
                        " --bitrate 200 --plane-qp-offsets 0 0 2 --p-qp-offset 3 --no-td "
                        "--subpel 2 --preset fast --no-decimation --bframes 0");
  ASSERT_EQ(rate.exit_code, 0) << rate.output;
  stats = read_json(gvid + ".stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["options"]["bitrate_kbps"], 200.0);
  EXPECT_EQ((*stats)["options"]["td_prediction"], false);
  EXPECT_EQ((*stats)["options"]["subpel"], 2);
  EXPECT_EQ((*stats)["options"]["shared_motion"], false);
  EXPECT_EQ((*stats)["options"]["inter_decimation"], false);
  EXPECT_LE((*stats)["summary"]["max_buffer_fullness_bits"].get<double>(),
            (*stats)["summary"]["buffer_bits"].get<double>());
  // Bit accounting: per frame type, plane and syntax group, adding up to the frame sizes.
  const auto& accounting = (*stats)["summary"]["syntax_bits"];
  EXPECT_EQ(accounting["I"]["frames"], 1);
  EXPECT_EQ(accounting["P"]["frames"], 2);
  EXPECT_GT(accounting["P"]["Y"]["motion"].get<double>(), 0.0);  // Y codes its own vectors
  double frame_bits = 0;
  for (const auto& f : (*stats)["frames"]) frame_bits += 8.0 * f["bytes"].get<double>();
  const double coded =
      accounting["I"]["all"]["total"].get<double>() + accounting["P"]["all"]["total"].get<double>();
  EXPECT_LT(coded, frame_bits);
  EXPECT_GT(coded, 0.8 * frame_bits);
  EXPECT_TRUE(contains(rate.output, "P frames (2), plane all")) << rate.output;

  const std::string in = (dir / "in").string();
  auto tiny = run_gvkit("encode " + in + " -o " + gvid + " --max-error-mm 0.00001");
  EXPECT_NE(tiny.exit_code, 0);
  EXPECT_TRUE(contains(tiny.output, "below the quantization error")) << tiny.output;
  auto mode = run_gvkit("encode " + in + " -o " + gvid + " --value-prediction rigid");
  EXPECT_NE(mode.exit_code, 0);
  EXPECT_TRUE(contains(mode.output, "value prediction 'rigid' unknown")) << mode.output;
  auto subpel = run_gvkit("encode " + in + " -o " + gvid + " --subpel 8");
  EXPECT_NE(subpel.exit_code, 0);
  EXPECT_TRUE(contains(subpel.output, "subpel 8 is not 0")) << subpel.output;
  auto threads = run_gvkit("encode " + in + " -o " + gvid + " --threads 0");
  EXPECT_NE(threads.exit_code, 0);
  EXPECT_TRUE(contains(threads.output, "threads 0 out of range")) << threads.output;
  auto lossless_rate = run_gvkit("encode " + in + " -o " + gvid + " --lossless --bitrate 100");
  EXPECT_NE(lossless_rate.exit_code, 0);
  EXPECT_TRUE(contains(lossless_rate.output, "rate control needs lossy coding"))
      << lossless_rate.output;
}

TEST(CliCodec, MaxTransformIsAnOptionAndInfoShowsTheLargerTransforms) {
  TempDir dir;
  write_frames(dir / "in", 3);
  const std::string in = (dir / "in").string(), gvid = (dir / "t.gvid").string();
  for (const int max_transform : {4, 16}) {
    auto enc = run_gvkit("encode " + in + " -o " + gvid + " --qp 0 --preset fast --max-transform " +
                         std::to_string(max_transform));
    ASSERT_EQ(enc.exit_code, 0) << enc.output;
    auto stats = read_json(gvid + ".stats.json");
    ASSERT_TRUE(stats.is_ok());
    EXPECT_EQ((*stats)["options"]["max_transform"], max_transform);
    auto info = run_gvkit("info " + gvid);
    ASSERT_EQ(info.exit_code, 0) << info.output;
    EXPECT_EQ(contains(info.output, "transforms      8x8 / 16x16 in 3 of 3 frames (format 1.6)"),
              max_transform == 16)
        << info.output;
  }
  auto bad = run_gvkit("encode " + in + " -o " + gvid + " --max-transform 32");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(contains(bad.output, "max transform 32 is not 4, 8 or 16")) << bad.output;
}

TEST(CliCodec, TargetPsnrMeetsTheTargetOnEveryFrameAndRecordsEachFramesQp) {
  TempDir dir;
  write_frames(dir / "in", 3);
  const std::string in = (dir / "in").string(), gvid = (dir / "cq.gvid").string();
  auto enc = run_gvkit("encode " + in + " -o " + gvid +
                       " --target-psnr 66 --intra-target-offset 2 --preset fast");
  ASSERT_EQ(enc.exit_code, 0) << enc.output;
  auto stats = read_json(gvid + ".stats.json");
  ASSERT_TRUE(stats.is_ok());
  EXPECT_EQ((*stats)["options"]["target_psnr_db"], 66.0);
  EXPECT_EQ((*stats)["options"]["intra_target_offset_db"], 2.0);
  EXPECT_EQ((*stats)["summary"]["frames_missing_target"], 0);
  EXPECT_GE((*stats)["summary"]["encodes_per_frame"].get<double>(), 1.0);
  ASSERT_EQ((*stats)["frames"].size(), 3u);
  for (const auto& f : (*stats)["frames"]) {
    const double target = f["frame"] == 0 ? 68.0 : 66.0;  // the I frame aims 2 dB higher
    EXPECT_GE(f["psnr_db"].get<double>(), target) << f.dump();
    EXPECT_TRUE(f.contains("qp") && f.contains("encodes")) << f.dump();
  }
  auto both = run_gvkit("encode " + in + " -o " + gvid + " --target-psnr 66 --bitrate 500");
  EXPECT_NE(both.exit_code, 0);
  EXPECT_TRUE(
      contains(both.output, "target PSNR: constant quality and a bitrate exclude each other"))
      << both.output;
  auto lossless = run_gvkit("encode " + in + " -o " + gvid + " --target-rms-mm 0.1 --lossless");
  EXPECT_NE(lossless.exit_code, 0);
  EXPECT_TRUE(contains(lossless.output, "target RMS: constant quality needs lossy coding"))
      << lossless.output;
}

TEST(CliCodec, BadOptionsAndInputsFailWithAMessage) {
  TempDir dir;
  write_frames(dir / "in", 1);
  const std::string in = (dir / "in").string(), out = (dir / "v.gvid").string();
  auto qp = run_gvkit("encode " + in + " -o " + out + " --qp 99");
  EXPECT_NE(qp.exit_code, 0);
  EXPECT_TRUE(contains(qp.output, "qp 99 out of range")) << qp.output;
  auto both = run_gvkit("encode " + in + " -o " + out + " --qp 3 --lossless");
  EXPECT_NE(both.exit_code, 0);
  auto preset = run_gvkit("encode " + in + " -o " + out + " --preset medium");
  EXPECT_NE(preset.exit_code, 0);
  EXPECT_TRUE(contains(preset.output, "preset 'medium'")) << preset.output;
  auto empty = run_gvkit("encode " + (dir / "nothing").string() + " -o " + out);
  EXPECT_NE(empty.exit_code, 0);
  EXPECT_FALSE(std::filesystem::exists(out));
  auto garbage = dir / "bad.gvid";
  std::ofstream(garbage) << "GVID but not really";
  auto dec = run_gvkit("decode " + garbage.string() + " -o " + (dir / "o").string());
  EXPECT_NE(dec.exit_code, 0);
  EXPECT_TRUE(contains(dec.output, "bad.gvid: header")) << dec.output;
}

}  // namespace
}  // namespace gvkit
