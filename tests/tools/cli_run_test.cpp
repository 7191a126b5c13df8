// `gvkit run` end to end on a tiny synthetic session: a .gvid comes out, an interrupted run
// resumes without computing finished frames again, a frame that facemap cannot map is listed
// while the rest of the video is still produced, and bad options are refused.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::run_gvkit;
using testing::TempDir;
namespace fs = std::filesystem;

using testing::contains;

// The indices of the frames a stage's stats.json lists as done.
std::vector<int64_t> done_frames(const fs::path& dir) {
  std::vector<int64_t> out;
  auto stats = read_json(dir / "stats.json");
  if (!stats.is_ok()) return out;
  for (const auto& f : (*stats)["frames"])
    if (!f.contains("error") && f.value("ok", true)) out.push_back(f["index"].get<int64_t>());
  return out;
}

const char* kTiny =
    " --frames 3 --size 256x256 --map-size 48x48 --preset fast --expressions neutral "
    "--exr-compression none";

TEST(CliRun, TinySyntheticSessionToGvidThenResumesWhereItStopped) {
  GVKIT_REQUIRE_SHARED_DATA(data);
  if (!fs::exists("/usr/share/dlib/shape_predictor_68_face_landmarks.dat"))
    GTEST_SKIP() << "dlib model absent (package libdlib-data)";
  TempDir dir;
  const fs::path work = dir / "work";
  auto first = run_gvkit("run synthetic -o " + work.string() + kTiny);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  ASSERT_TRUE(fs::exists(work / "face.gvid"));
  for (const char* log : {"synth", "reconstruct", "clean", "map", "encode", "decode"})
    EXPECT_TRUE(fs::exists(work / "logs" / (std::string(log) + ".log"))) << log;
  EXPECT_TRUE(contains(first.output, "stage")) << first.output;  // the table
  EXPECT_TRUE(contains(first.output, "bits/vertex/frame")) << first.output;
  auto record = read_json(work / "run.json");
  ASSERT_TRUE(record.is_ok());
  EXPECT_EQ((*record)["complete"], true);
  const auto mapped = done_frames(work / "gv");
  ASSERT_GE(mapped.size(), 2u) << first.output;
  auto decoded = list_frame_files(work / "decoded", ".exr");
  ASSERT_TRUE(decoded.is_ok());
  EXPECT_EQ(decoded->size(), mapped.size());
  // --exr-compression reaches the stages that write geometry images.
  auto map_stats = read_json(work / "gv" / "stats.json");
  auto decode_stats = read_json(work / "decoded" / "stats.json");
  ASSERT_TRUE(map_stats.is_ok() && decode_stats.is_ok());
  EXPECT_EQ((*map_stats)["options"]["exr_compression"], "none");
  EXPECT_EQ((*decode_stats)["exr_compression"], "none");

  // Interrupted in facemap map: its last frame is gone and its stats.json is unfinished.
  const fs::path last = frame_path(work / "gv", mapped.back(), ".exr");
  const fs::path kept = frame_path(work / "gv", mapped.front(), ".exr");
  const fs::path scan = frame_path(work / "scans", 0, ".exr");
  const auto kept_time = fs::last_write_time(kept), scan_time = fs::last_write_time(scan);
  fs::remove(last);
  auto stats = read_json(work / "gv" / "stats.json");
  ASSERT_TRUE(stats.is_ok());
  (*stats)["complete"] = false;
  ASSERT_TRUE(write_json(work / "gv" / "stats.json", *stats).is_ok());
  auto second = run_gvkit("run synthetic -o " + work.string() + kTiny);
  ASSERT_EQ(second.exit_code, 0) << second.output;
  EXPECT_TRUE(contains(second.output, "reconstruct: outputs complete from an earlier run; skipped"))
      << second.output;
  EXPECT_TRUE(contains(second.output, "clean: outputs complete from an earlier run; skipped"))
      << second.output;
  EXPECT_TRUE(contains(second.output, std::to_string(mapped.size() - 1) + " of " +
                                          std::to_string(mapped.size()) +
                                          " frames were already done"))
      << second.output;
  EXPECT_TRUE(fs::exists(last));
  EXPECT_EQ(fs::last_write_time(kept), kept_time);  // not mapped again
  EXPECT_EQ(fs::last_write_time(scan), scan_time);  // not reconstructed again
  EXPECT_EQ(done_frames(work / "gv"), mapped);

  // A frame facemap cannot map: the others still make the video, the failure is listed.
  const int64_t broken = mapped.front();
  std::ofstream(frame_path(work / "faces", broken, ".ply")) << "ply\nnot really\n";
  fs::remove(frame_path(work / "gv", broken, ".exr"));
  auto third = run_gvkit("run synthetic -o " + work.string() + kTiny);
  ASSERT_EQ(third.exit_code, 0) << third.output;
  EXPECT_TRUE(contains(third.output, "map: 1 frame(s) failed")) << third.output;
  EXPECT_TRUE(contains(third.output, "frame " + std::to_string(broken) + ": ")) << third.output;
  decoded = list_frame_files(work / "decoded", ".exr");
  auto enc = read_json(work / "face.gvid.stats.json");
  ASSERT_TRUE(enc.is_ok());
  EXPECT_EQ((*enc)["summary"]["frames"].get<size_t>(), mapped.size() - 1);

  // The table on its own.
  auto summary = run_gvkit("summary " + work.string());
  ASSERT_EQ(summary.exit_code, 0) << summary.output;
  EXPECT_TRUE(contains(summary.output, "reconstruct")) << summary.output;
  EXPECT_TRUE(contains(summary.output,
                       std::to_string(mapped.size() - 1) + "/" + std::to_string(mapped.size())))
      << summary.output;
}

TEST(CliRun, BadOptionsAndInputsFailWithAMessage) {
  TempDir dir;
  const std::string work = (dir / "w").string();
  auto frames = run_gvkit("run synthetic -o " + work + " --frames 0");
  EXPECT_NE(frames.exit_code, 0);
  EXPECT_TRUE(contains(frames.output, "--frames must be >= 1")) << frames.output;
  auto size = run_gvkit("run synthetic -o " + work + " --map-size 12");
  EXPECT_NE(size.exit_code, 0);
  EXPECT_TRUE(contains(size.output, "--map-size")) << size.output;
  auto qp = run_gvkit("run synthetic -o " + work + " --qp 99");
  EXPECT_NE(qp.exit_code, 0);
  EXPECT_TRUE(contains(qp.output, "qp 99")) << qp.output;
  auto preset = run_gvkit("run synthetic -o " + work + " --preset medium");
  EXPECT_NE(preset.exit_code, 0);
  EXPECT_TRUE(contains(preset.output, "medium")) << preset.output;
  auto compression = run_gvkit("run synthetic -o " + work + " --exr-compression piz");
  EXPECT_NE(compression.exit_code, 0);
  EXPECT_TRUE(contains(compression.output, "--exr-compression")) << compression.output;
  auto input = run_gvkit("run " + (dir / "nowhere").string() + " -o " + work);
  EXPECT_NE(input.exit_code, 0);
  EXPECT_TRUE(contains(input.output, "nowhere: no such folder")) << input.output;
  EXPECT_FALSE(fs::exists(dir / "w" / "run.json"));
  auto summary = run_gvkit("summary " + (dir / "nowhere").string());
  EXPECT_NE(summary.exit_code, 0);
  EXPECT_TRUE(contains(summary.output, "no such folder")) << summary.output;
  auto empty = run_gvkit("summary " + dir.path().string());
  EXPECT_NE(empty.exit_code, 0);
  EXPECT_TRUE(contains(empty.output, "no stage outputs")) << empty.output;
}

}  // namespace
}  // namespace gvkit
