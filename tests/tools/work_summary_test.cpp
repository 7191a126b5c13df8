// The result table of a work folder, built from each stage's stats.json (tools/work_summary).
#include "work_summary.hpp"

#include <fstream>

#include <gtest/gtest.h>

#include "gvkit/core/frame_files.hpp"
#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"

namespace gvkit::tools {
namespace {
using testing::TempDir;
namespace fs = std::filesystem;

using testing::contains;

void write(const fs::path& path, const nlohmann::json& j) {
  ASSERT_TRUE(ensure_directory(path.parent_path()).is_ok());
  ASSERT_TRUE(write_json(path, j).is_ok());
}

// A work folder as `gvkit run` leaves it: three frames, the middle one lost in facemap clean.
void write_work_folder(const fs::path& w) {
  write(w / "session" / "session.json",
        {{"image_size", {256, 192}},
         {"pattern", {{"name", "psp3-f16"}}},
         {"frames", {{{"index", 0}}, {{"index", 1}}, {{"index", 2}}}}});
  write(w / "scans" / "stats.json", {{"summary",
                                      {{"frames", 3},
                                       {"rms_depth_error_mm", 0.137},
                                       {"face_interior_rms_mm", 0.1255},
                                       {"max_depth_error_mm", 2.19},
                                       {"mean_valid_share", 0.293}}},
                                     {"frames", {{{"index", 0}}, {{"index", 1}}, {{"index", 2}}}}});
  write(w / "faces" / "stats.json",
        {{"summary", {{"frames", 3}, {"ok", 2}, {"failed", 1}, {"mean_frame_ms", 1400.0}}},
         {"frames",
          {{{"index", 0}, {"ok", true}},
           {{"index", 1}, {"ok", false}, {"error", "frame 1: landmark 60 lies 30 mm off the mesh"}},
           {{"index", 2}, {"ok", true}}}}});
  write(w / "gv" / "stats.json", {{"summary",
                                   {{"frames", 2},
                                    {"mapped", 2},
                                    {"failed", 0},
                                    {"flipped_total", 4},
                                    {"feature_drift_px_mean", 1.25},
                                    {"key_feature_drift_px_mean", 0.5},
                                    {"key_feature_drift_px_max", 0.75},
                                    {"temporal_mse_mean_mm2", 0.0123}}},
                                  {"frames", {{{"index", 0}}, {{"index", 2}}}}});
  write(w / "face.gvid.stats.json", {{"summary",
                                      {{"frames", 2},
                                       {"bits_per_vertex_per_frame", 0.93},
                                       {"psnr_db", 70.125},
                                       {"max_mm", 0.05},
                                       {"normal_p95_deg", 1.875},
                                       {"hausdorff_mm", 0.046875},
                                       {"file_bytes", 12345}}}});
  write(w / "decoded" / "stats.json",
        {{"summary", {{"frames", 2}, {"failed_frames", 0}, {"decode_fps", 120.0}}},
         {"frames", {{{"frame", 0}, {"status", "ok"}}, {{"frame", 1}, {"status", "ok"}}}}});
  write(w / "compare.stats.json", {{"summary",
                                    {{"frames", 2},
                                     {"normal_mean_deg", 0.75},
                                     {"normal_p95_deg", 1.875},
                                     {"normal_max_deg", 12.5},
                                     {"hausdorff_mm", 0.046875},
                                     {"outline_hausdorff_mm", 0.03125}}}});
  write(w / "run.json", {{"stages",
                          {{{"name", "synth"}, {"seconds", 1.5}},
                           {{"name", "reconstruct"}, {"seconds", 2.0}, {"state", "kept"}},
                           {{"name", "clean"}, {"seconds", 3.25}},
                           {{"name", "map"}, {"seconds", 4.0}},
                           {{"name", "encode"}, {"seconds", 0.5}},
                           {{"name", "decode"}, {"seconds", 0.25}},
                           {{"name", "compare"}, {"seconds", 0.5}}}}});
}

TEST(WorkSummary, ReadsEveryStageInOrderWithFramesInAndOut) {
  TempDir dir;
  write_work_folder(dir.path());
  auto stages = summarize_work_folder(dir.path());
  ASSERT_TRUE(stages.is_ok()) << stages.status().message();
  ASSERT_EQ(stages->size(), 7u);
  const std::vector<std::string> names = {"synth",  "reconstruct", "clean",  "map",
                                          "encode", "decode",      "compare"};
  for (size_t i = 0; i < names.size(); ++i) EXPECT_EQ((*stages)[i].stage, names[i]);
  const StageSummary& clean = (*stages)[2];
  EXPECT_EQ(clean.frames_in, 3);
  EXPECT_EQ(clean.frames_out, 2);
  ASSERT_EQ(clean.failures.size(), 1u);
  EXPECT_EQ(clean.failures[0], "frame 1: landmark 60 lies 30 mm off the mesh");
  EXPECT_DOUBLE_EQ(clean.seconds, 3.25);
  EXPECT_EQ((*stages)[0].frames_out, 3);
  EXPECT_EQ((*stages)[5].frames_out, 2);
}

TEST(WorkSummary, TableShowsTheFiguresTimesAndLostFrames) {
  TempDir dir;
  write_work_folder(dir.path());
  const std::string table = format_summary_table(summarize_work_folder(dir.path()).value());
  EXPECT_TRUE(contains(table, "RMS depth error 0.1370 mm (face interior 0.1255 mm)")) << table;
  EXPECT_TRUE(contains(table, "2/3")) << table;  // clean lost a frame
  EXPECT_TRUE(contains(table, "256x192 fringe images, pattern psp3-f16")) << table;
  EXPECT_TRUE(contains(table, "flips 4, feature drift 1.25 px (key points 0.50, max 0.75)"))
      << table;
  EXPECT_TRUE(contains(table, "temporal MSE 0.0123 mm^2")) << table;
  EXPECT_TRUE(contains(table, "0.9300 bits/vertex/frame, PSNR 70.12 dB")) << table;
  EXPECT_TRUE(contains(table, "normal error p95 1.88 deg, Hausdorff 0.047 mm, 12345 bytes"))
      << table;
  EXPECT_TRUE(contains(table,
                       "decoded vs input: normal error mean 0.75 / p95 1.88 / max 12.5 deg, "
                       "Hausdorff 0.047 mm (outline 0.031 mm)"))
      << table;
  EXPECT_TRUE(contains(table, "3.2 s")) << table;   // clean's time
  EXPECT_TRUE(contains(table, "2.0 s*")) << table;  // reconstruct's, from an earlier run
  EXPECT_TRUE(contains(table, "* kept from an earlier run")) << table;
  EXPECT_TRUE(contains(table, "12.0 s")) << table;  // the total
  EXPECT_TRUE(contains(table, "clean: 1 frame(s) failed:\n  frame 1: landmark 60")) << table;
  EXPECT_FALSE(contains(table, "decode: ")) << table;  // no decode failures
}

TEST(WorkSummary, MissingStagesAreLeftOutAndBadFilesNamed) {
  TempDir dir;
  write(dir / "scans" / "stats.json", {{"summary", {{"frames", 2}, {"mean_valid_share", 0.5}}}});
  auto stages = summarize_work_folder(dir.path());
  ASSERT_TRUE(stages.is_ok());
  ASSERT_EQ(stages->size(), 1u);
  EXPECT_EQ((*stages)[0].seconds, -1);
  EXPECT_TRUE(contains(format_summary_table(*stages), "valid share 0.500"));
  ASSERT_TRUE(ensure_directory(dir / "faces").is_ok());
  std::ofstream(dir / "faces" / "stats.json") << "{ not json";
  auto bad = summarize_work_folder(dir.path());
  ASSERT_FALSE(bad.is_ok());
  EXPECT_TRUE(contains(bad.status().message(), "faces/stats.json")) << bad.status().message();
  EXPECT_FALSE(summarize_work_folder(dir / "nowhere").is_ok());
}

}  // namespace
}  // namespace gvkit::tools
