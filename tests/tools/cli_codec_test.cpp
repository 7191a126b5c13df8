// `gvkit encode`, `gvkit decode` and `gvkit info` on .gvid streams, as a user runs them.
#include <fstream>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
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
  EXPECT_EQ((*stats)["format"], "2.0");
  EXPECT_EQ((*stats)["profile"], "lossless");
  EXPECT_EQ((*stats)["frames"].size(), 2u);

  auto info = run_gvkit("info " + gvid);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_TRUE(contains(info.output, ".gvid geometry video"));
  EXPECT_TRUE(contains(info.output, "format          2.0, profile lossless")) << info.output;
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

// --exr-compression changes how decode and export write the EXRs, never the values.
TEST(CliCodec, EveryExrCompressionWritesTheSameValues) {
  TempDir dir;
  write_frames(dir / "in", 2);
  const std::string gvid = (dir / "v.gvid").string();
  ASSERT_EQ(
      run_gvkit("encode " + (dir / "in").string() + " -o " + gvid + " --preset fast").exit_code, 0);
  ASSERT_EQ(run_gvkit("decode " + gvid + " -o " + (dir / "zip").string()).exit_code, 0);
  for (const std::string c : {"rle", "none"}) {
    auto dec =
        run_gvkit("decode " + gvid + " -o " + (dir / c).string() + " --exr-compression " + c);
    ASSERT_EQ(dec.exit_code, 0) << dec.output;
    auto stats = read_json(dir / c / "stats.json");
    ASSERT_TRUE(stats.is_ok());
    EXPECT_EQ((*stats)["exr_compression"], c);
    auto exported = run_gvkit("export " + gvid + " --format exr -o " + (dir / ("x" + c)).string() +
                              " --exr-compression " + c);
    ASSERT_EQ(exported.exit_code, 0) << exported.output;
    for (int f = 0; f < 2; ++f) {
      auto zip = read_geometry_image_exr(frame_path(dir / "zip", f, ".exr"));
      ASSERT_TRUE(zip.is_ok());
      for (const auto& folder : {dir / c, dir / ("x" + c)}) {
        auto other = read_geometry_image_exr(frame_path(folder, f, ".exr"));
        ASSERT_TRUE(other.is_ok()) << other.status().message();
        EXPECT_TRUE(testing::same_samples(other->xyz_mm, zip->xyz_mm)) << folder << " frame " << f;
        EXPECT_TRUE(testing::same_samples(other->domain_mask, zip->domain_mask)) << folder;
      }
    }
  }
  // Uncompressed files are the larger.
  EXPECT_GT(std::filesystem::file_size(frame_path(dir / "none", 0, ".exr")),
            std::filesystem::file_size(frame_path(dir / "zip", 0, ".exr")));
  auto bad =
      run_gvkit("decode " + gvid + " -o " + (dir / "bad").string() + " --exr-compression piz");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(contains(bad.output, "--exr-compression")) << bad.output;
  EXPECT_TRUE(contains(bad.output, "'piz'")) << bad.output;
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

  // One thread writes and measures the same: the same files and figures.
  auto one = run_gvkit("decode " + gvid + " -o " + (dir / "one").string() + " --reference " +
                       (dir / "in").string() + " --threads 1");
  ASSERT_EQ(one.exit_code, 0) << one.output;
  auto one_stats = read_json(dir / "one" / "stats.json");
  ASSERT_TRUE(one_stats.is_ok());
  EXPECT_EQ((*one_stats)["frames"], (*decoded)["frames"]);
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(read_file(frame_path(dir / "one", i, ".exr")).value(),
              read_file(frame_path(dir / "out", i, ".exr")).value())
        << i;
  auto threads = run_gvkit("decode " + gvid + " -o " + (dir / "t").string() + " --threads 17");
  EXPECT_NE(threads.exit_code, 0);
  EXPECT_TRUE(contains(threads.output, "--threads must be 0..16")) << threads.output;

  // A reference that does not match the stream is named.
  write_frames(dir / "two", 2);
  auto bad = run_gvkit("decode " + gvid + " -o " + (dir / "out2").string() + " --reference " +
                       (dir / "two").string());
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(contains(bad.output, "two: 2 frame_NNNNNN.exr files for 3 frames")) << bad.output;
}

// --measures points: the same stream, the point error per frame and in the summary, no surface
// figures; an unknown value is refused naming the option.
TEST(CliCodec, PointMeasuresLeaveTheSurfaceFiguresOutAndTheStreamAlone) {
  TempDir dir;
  write_frames(dir / "in", 3);
  const std::string in = (dir / "in").string();
  const std::string full = (dir / "full.gvid").string(), points = (dir / "points.gvid").string();
  auto a = run_gvkit("encode " + in + " -o " + full + " --qp 12 --preset fast");
  ASSERT_EQ(a.exit_code, 0) << a.output;
  auto b = run_gvkit("encode " + in + " -o " + points + " --qp 12 --preset fast --measures points");
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_FALSE(contains(b.output, "Hausdorff")) << b.output;
  EXPECT_TRUE(contains(b.output, "PSNR")) << b.output;
  EXPECT_EQ(read_file(full).value(), read_file(points).value());
  auto fs = read_json(full + ".stats.json"), ps = read_json(points + ".stats.json");
  ASSERT_TRUE(fs.is_ok() && ps.is_ok());
  EXPECT_EQ((*fs)["options"]["measures"], "full");
  EXPECT_EQ((*ps)["options"]["measures"], "points");
  for (const char* key : {"psnr_db", "rms_mm", "max_mm"})
    EXPECT_EQ((*ps)["summary"][key], (*fs)["summary"][key]) << key;
  EXPECT_FALSE((*ps)["summary"].contains("hausdorff_mm"));
  EXPECT_TRUE((*fs)["summary"].contains("hausdorff_mm"));
  ASSERT_EQ((*ps)["frames"].size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ((*ps)["frames"][i]["max_mm"], (*fs)["frames"][i]["max_mm"]) << i;
    EXPECT_FALSE((*ps)["frames"][i].contains("normal_p95_deg")) << i;
  }
  auto bad = run_gvkit("encode " + in + " -o " + points + " --measures none");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(contains(bad.output, "--measures")) << bad.output;
  EXPECT_EQ(read_file(full).value(), read_file(points).value());  // left as it was
}

TEST(CliCodec, BFramesAreOptionsInfoShowsTheTypesAndDecodeWritesDisplayOrder) {
  TempDir dir;
  write_frames(dir / "in", 5);
  const std::string gvid = (dir / "v.gvid").string();
  auto enc = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid +
                       " --lossless --preset fast --tune bframes=2 --tune b-qp-offset=3");
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
  auto bad = run_gvkit("encode " + (dir / "in").string() + " -o " + gvid + " --tune bframes=4");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(contains(bad.output, "B frames 4 out of range")) << bad.output;
}

// Every tool switch is a --tune key: it reaches the encoder (the stats record it, the stream
// changes) and `gvkit info` shows the frame-level tools it turns on or off; every stream decodes.
TEST(CliCodec, TuneKeysReachTheEncoderAndInfoShowsTheTools) {
  TempDir dir;
  write_frames(dir / "in", 4);
  const std::string in = (dir / "in").string();
  struct Case {
    std::string tunes;                                          // --tune arguments
    std::vector<std::pair<std::string, nlohmann::json>> stats;  // options in stats.json
    std::vector<std::string> shown;  // what `gvkit info` shows with the defaults, not the tunes
  };
  const std::vector<Case> cases = {
      {"cross-plane=off --tune deblock=off --tune temporal-contexts=off --tune max-transform=4 "
       "--tune refs=1 --tune bframes=0 --tune cross-plane-contexts=off",
       {{"cross_plane", false},
        {"deblocking", false},
        {"temporal_contexts", false},
        {"max_transform", 4},
        {"refs", 1},
        {"bframes", 0},
        {"cross_plane_contexts", false}},
       {"  cross-plane  ", "  deblocking", "temporal-contexts", "transforms      8x8 / 16x16",
        "refs 2", "  B  ", "cross-plane-contexts"}},
      {"merge=off --tune td16=off --tune quadratic-intra=off --tune rdoq=off",
       {{"merge", false}, {"td16", false}, {"quadratic_intra", false}, {"rdoq", false}},
       {}},
      {"resolution=full --tune subpel=2 --tune td=no --tune plane-qp-offsets=0,0,2",
       {{"resolution", "full"},
        {"subpel", 2},
        {"td_prediction", false},
        {"plane_qp_offsets", nlohmann::json::array({0, 0, 2})}},
       {}},
  };
  const std::string base = (dir / "base.gvid").string();
  auto enc = run_gvkit("encode " + in + " -o " + base + " --qp 6 --gop 4");
  ASSERT_EQ(enc.exit_code, 0) << enc.output;
  auto base_info = run_gvkit("info " + base);
  ASSERT_EQ(base_info.exit_code, 0) << base_info.output;
  const auto base_bytes = read_file(base);
  ASSERT_TRUE(base_bytes.is_ok());
  for (size_t k = 0; k < cases.size(); ++k) {
    const Case& c = cases[k];
    SCOPED_TRACE(c.tunes);
    const std::string gvid = (dir / ("t" + std::to_string(k) + ".gvid")).string();
    enc = run_gvkit("encode " + in + " -o " + gvid + " --qp 6 --gop 4 --tune " + c.tunes);
    ASSERT_EQ(enc.exit_code, 0) << enc.output;
    auto stats = read_json(gvid + ".stats.json");
    ASSERT_TRUE(stats.is_ok());
    for (const auto& [name, value] : c.stats) EXPECT_EQ((*stats)["options"][name], value) << name;
    EXPECT_EQ((*stats)["format"], "2.0");
    EXPECT_EQ((*stats)["profile"], "main");
    EXPECT_FALSE(*read_file(gvid) == *base_bytes);
    auto info = run_gvkit("info " + gvid);
    ASSERT_EQ(info.exit_code, 0) << info.output;
    EXPECT_TRUE(contains(info.output, "format          2.0, profile main")) << info.output;
    for (const std::string& shown : c.shown) {
      EXPECT_TRUE(contains(base_info.output, shown)) << shown << base_info.output;
      EXPECT_FALSE(contains(info.output, shown)) << shown << info.output;
    }
    auto dec = run_gvkit("decode " + gvid + " -o " + (dir / ("t" + std::to_string(k))).string());
    ASSERT_EQ(dec.exit_code, 0) << dec.output;
  }
  // Tunes that turn tools on: half resolution in every frame, partitions in the slow preset.
  const std::string half = (dir / "half.gvid").string();
  enc = run_gvkit("encode " + in + " -o " + half + " --tune resolution=half --tune partitions=on");
  ASSERT_EQ(enc.exit_code, 0) << enc.output;
  const auto info = run_gvkit("info " + half);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  size_t shown = 0;
  for (size_t at = info.output.find("half-resolution"); at != std::string::npos;
       at = info.output.find("half-resolution", at + 1))
    ++shown;
  EXPECT_EQ(shown, 4u) << info.output;
  EXPECT_EQ(run_gvkit("decode " + half + " -o " + (dir / "half").string()).exit_code, 0);
}

TEST(CliCodec, TuneHelpListsTheKeysAndBadTunesFailNamingThem) {
  TempDir dir;
  write_frames(dir / "in", 1);
  const std::string in = (dir / "in").string(), out = (dir / "v.gvid").string();
  auto help = run_gvkit("encode --tune help");  // no input or output needed
  ASSERT_EQ(help.exit_code, 0) << help.output;
  for (const char* key : {"merge", "td16", "quadratic-intra", "deblock", "refs", "resolution"})
    EXPECT_TRUE(contains(help.output, std::string("  ") + key + " ")) << key << help.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  const std::pair<const char*, const char*> bad[] = {
      {"--tune merge=maybe", "tune merge=maybe: not on or off (on|off)"},
      {"--tune frobnicate=1", "tune frobnicate=1: unknown key"},
      {"--tune merge", "tune 'merge': not key=value"},
      {"--tune max-transform=32", "max transform 32 is not 4, 8 or 16"},
      {"--tune resolution=quarter", "resolution 'quarter' unknown"},
      {"--tune plane-qp-offsets=1,2", "three integers X,Y,Z"},
      {"--profile intra --tune bframes=2", "profile intra: I frames only, no B frames"},
  };
  for (const auto& [args, message] : bad) {
    auto r = run_gvkit("encode " + in + " -o " + out + " " + args);
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_TRUE(contains(r.output, message)) << args << "\n" << r.output;
  }
  // The per-tool flags of the 1.x encoder are gone.
  auto old = run_gvkit("encode " + in + " -o " + out + " --no-merge");
  EXPECT_NE(old.exit_code, 0);
}

// The profile follows the options (lossless, intra, main) or is chosen; `gvkit info` and the stats
// name it.
TEST(CliCodec, ProfilesAreNamedInTheStreamTheStatsAndInfo) {
  TempDir dir;
  write_frames(dir / "in", 3);
  const std::string in = (dir / "in").string();
  const std::pair<const char*, const char*> cases[] = {
      {"--qp 12", "main"},
      {"--intra-only", "intra"},
      {"--lossless", "lossless"},
      {"--max-error-mm 0.05", "lossless"},
      {"--profile intra", "intra"},
      {"--profile lossless --preset fast", "lossless"},
      {"--profile main --lossless", "main"}};
  for (const auto& [args, profile] : cases) {
    SCOPED_TRACE(args);
    const std::string gvid = (dir / (std::string(profile) + ".gvid")).string();
    auto enc = run_gvkit("encode " + in + " -o " + gvid + " " + args);
    ASSERT_EQ(enc.exit_code, 0) << enc.output;
    auto stats = read_json(gvid + ".stats.json");
    ASSERT_TRUE(stats.is_ok());
    EXPECT_EQ((*stats)["profile"], profile);
    auto info = run_gvkit("info " + gvid);
    ASSERT_EQ(info.exit_code, 0) << info.output;
    EXPECT_TRUE(contains(info.output, std::string("format          2.0, profile ") + profile))
        << info.output;
    if (std::string(profile) == "intra") {
      EXPECT_TRUE(contains(info.output, "frame types     3 I, 0 P, 0 B")) << info.output;
    }
    if (std::string(args) == "--profile lossless --preset fast") {
      EXPECT_LT((*stats)["summary"]["max_mm"].get<double>(), 0.01);  // the quantization only
    }
  }
  auto bad = run_gvkit("encode " + in + " -o " + (dir / "x.gvid").string() + " --profile high");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(contains(bad.output, "profile 'high' unknown")) << bad.output;
}

// A legacy 1.x stream is still read: `gvkit info` says which version it is and that gvkit writes
// 2.0; it decodes.
TEST(CliCodec, InfoSaysALegacyStreamsVersionAndItDecodes) {
  TempDir dir;
  const std::string v1 =
      GVKIT_SOURCE_DIR "/tests/golden/v1/analytic_temporal_slow_qp6_ibpbp_v1_9_48.gvid";
  auto info = run_gvkit("info " + v1);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_TRUE(contains(info.output,
                       "format          1.9 (legacy 1.x, read-only: gvkit writes "
                       "format 2.0)"))
      << info.output;
  EXPECT_TRUE(contains(info.output, "full-packet-header")) << info.output;
  auto dec = run_gvkit("decode " + v1 + " -o " + (dir / "out").string());
  ASSERT_EQ(dec.exit_code, 0) << dec.output;
  EXPECT_TRUE(std::filesystem::exists(frame_path(dir / "out", 4, ".exr")));
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
                       " --max-error-mm 0.05 --gop 3 --tune value-prediction=affine --threads 2 "
                       "--tune shared-motion=on --preset fast");
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
                        " --bitrate 200 --tune plane-qp-offsets=0,0,2 --tune p-qp-offset=3 --tune "
                        "td=off --tune subpel=2 --preset fast --tune decimation=off --tune "
                        "bframes=0");
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
  auto mode = run_gvkit("encode " + in + " -o " + gvid + " --tune value-prediction=rigid");
  EXPECT_NE(mode.exit_code, 0);
  EXPECT_TRUE(contains(mode.output, "value prediction 'rigid' unknown")) << mode.output;
  auto subpel = run_gvkit("encode " + in + " -o " + gvid + " --tune subpel=8");
  EXPECT_NE(subpel.exit_code, 0);
  EXPECT_TRUE(contains(subpel.output, "subpel 8 is not 0")) << subpel.output;
  auto threads = run_gvkit("encode " + in + " -o " + gvid + " --threads 17");
  EXPECT_NE(threads.exit_code, 0);
  EXPECT_TRUE(contains(threads.output, "threads 17 out of range")) << threads.output;
  // 0 (the default) is the hardware's threads: the same stream as one thread.
  const std::string t1 = (dir / "t1.gvid").string(), t0 = (dir / "t0.gvid").string();
  ASSERT_EQ(run_gvkit("encode " + in + " -o " + t1 + " --threads 1").exit_code, 0);
  auto automatic = run_gvkit("encode " + in + " -o " + t0);
  ASSERT_EQ(automatic.exit_code, 0) << automatic.output;
  EXPECT_EQ(read_file(t1).value(), read_file(t0).value());
  auto lossless_rate = run_gvkit("encode " + in + " -o " + gvid + " --lossless --bitrate 100");
  EXPECT_NE(lossless_rate.exit_code, 0);
  EXPECT_TRUE(contains(lossless_rate.output, "--bitrate excludes --lossless"))
      << lossless_rate.output;
  // A profile that implies lossless coding: the library's check names it.
  auto profile_rate =
      run_gvkit("encode " + in + " -o " + gvid + " --profile lossless --bitrate 100");
  EXPECT_NE(profile_rate.exit_code, 0);
  EXPECT_TRUE(contains(profile_rate.output, "rate control needs lossy coding"))
      << profile_rate.output;
}

TEST(CliCodec, FramesBeyondTheFrameCacheAreReadAgainForTheSameStream) {
  TempDir dir;
  write_frames(dir / "in", 7);
  const std::string in = (dir / "in").string();
  const std::string kept = (dir / "kept.gvid").string(), reread = (dir / "reread.gvid").string();
  auto all = run_gvkit("encode " + in + " -o " + kept + " --preset fast --qp 6");
  ASSERT_EQ(all.exit_code, 0) << all.output;
  EXPECT_FALSE(contains(all.output, "read again")) << all.output;
  // No frame kept between the two readings: every frame read again, on two threads.
  auto none = run_gvkit("encode " + in + " -o " + reread +
                        " --preset fast --qp 6 --frame-cache-mb 0 --threads 2");
  ASSERT_EQ(none.exit_code, 0) << none.output;
  EXPECT_TRUE(contains(none.output, "0 of 7 frames kept in memory")) << none.output;
  EXPECT_EQ(read_file(kept).value(), read_file(reread).value());
  auto a = read_json(kept + ".stats.json"), b = read_json(reread + ".stats.json");
  ASSERT_TRUE(a.is_ok() && b.is_ok());
  EXPECT_EQ((*a)["frames"], (*b)["frames"]);
  EXPECT_EQ((*b)["options"]["frame_cache_mb"], 0);

  auto negative = run_gvkit("encode " + in + " -o " + reread + " --frame-cache-mb -1");
  EXPECT_NE(negative.exit_code, 0);
  EXPECT_TRUE(contains(negative.output, "--frame-cache-mb")) << negative.output;
  // A frame whose domain mask differs from frame 0's is named by its file; the stream written
  // before is left as it was.
  auto frame = read_geometry_image_exr(frame_path(dir / "in", 3, ".exr")).value();
  frame.domain_mask.at<uint8_t>(16, 16) ^= 255;
  ASSERT_TRUE(write_geometry_image_exr(frame_path(dir / "in", 3, ".exr"), frame).is_ok());
  auto bad = run_gvkit("encode " + in + " -o " + reread + " --frame-cache-mb 0");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(contains(bad.output, "frame_000003.exr: frame 3: domain mask differs from frame 0"))
      << bad.output;
  EXPECT_EQ(read_file(kept).value(), read_file(reread).value());
}

TEST(CliCodec, QualityMeetsTheTargetOnEveryFrameAndRecordsEachFramesQp) {
  TempDir dir;
  write_frames(dir / "in", 3);
  const std::string in = (dir / "in").string(), gvid = (dir / "cq.gvid").string();
  auto enc = run_gvkit("encode " + in + " -o " + gvid +
                       " --quality 66 --tune intra-target-offset=2 --preset fast");
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
  auto both = run_gvkit("encode " + in + " -o " + gvid + " --quality 66 --bitrate 500");
  EXPECT_NE(both.exit_code, 0);
  EXPECT_TRUE(contains(both.output, "--quality excludes --bitrate")) << both.output;
  auto lossless =
      run_gvkit("encode " + in + " -o " + gvid + " --tune target-rms-mm=0.1 --lossless");
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
  // Unreadable frames: the first one in frame order is named, however the reading threads ran.
  write_frames(dir / "broken", 6);
  std::ofstream(frame_path(dir / "broken", 2, ".exr"), std::ios::trunc) << "not an EXR";
  std::ofstream(frame_path(dir / "broken", 4, ".exr"), std::ios::trunc) << "not an EXR";
  for (int round = 0; round < 3; ++round) {
    auto broken = run_gvkit("encode " + (dir / "broken").string() + " -o " + out + " --threads 4");
    EXPECT_NE(broken.exit_code, 0);
    EXPECT_TRUE(contains(broken.output, "frame_000002.exr: not a readable EXR")) << broken.output;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
  auto garbage = dir / "bad.gvid";
  std::ofstream(garbage) << "GVID but not really";
  auto dec = run_gvkit("decode " + garbage.string() + " -o " + (dir / "o").string());
  EXPECT_NE(dec.exit_code, 0);
  EXPECT_TRUE(contains(dec.output, "bad.gvid: header")) << dec.output;
}

}  // namespace
}  // namespace gvkit
