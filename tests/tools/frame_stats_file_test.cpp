// FrameStatsFile: the stats.json of the per-frame commands, written as frames finish and read
// back when a run resumes (tools/tool_support).
#include <gtest/gtest.h>

#include "gvkit/core/json_io.hpp"
#include "support/test_support.hpp"
#include "tool_support.hpp"

namespace gvkit::tools {
namespace {
using testing::TempDir;

TEST(FrameStatsFile, EntriesAreOnDiskAsFramesFinishAndCompleteAfterFinish) {
  TempDir dir;
  const nlohmann::json header = {{"command", "test"}, {"options", {{"size", 3}}}};
  FrameStatsFile stats(dir.path(), header, false);
  ASSERT_TRUE(stats.record(2, {{"index", 2}, {"v", 20}}).is_ok());
  ASSERT_TRUE(stats.record(0, {{"index", 0}, {"v", 0}}).is_ok());
  auto partial = read_json(dir / "stats.json");
  ASSERT_TRUE(partial.is_ok());
  EXPECT_EQ((*partial)["complete"], false);
  ASSERT_EQ((*partial)["frames"].size(), 2u);
  EXPECT_EQ((*partial)["frames"][0]["index"], 0);  // by index, not by arrival
  EXPECT_EQ((*partial)["command"], "test");
  ASSERT_TRUE(stats.finish({{"frames", 2}}).is_ok());
  auto done = read_json(dir / "stats.json");
  ASSERT_TRUE(done.is_ok());
  EXPECT_EQ((*done)["complete"], true);
  EXPECT_EQ((*done)["summary"]["frames"], 2);
  EXPECT_EQ((*done)["frames"][1]["v"], 20);
}

TEST(FrameStatsFile, ResumeOffersEarlierEntriesOnlyForTheSameOptions) {
  TempDir dir;
  const nlohmann::json header = {{"command", "test"}, {"options", {{"size", 3}}}};
  {
    FrameStatsFile first(dir.path(), header, false);
    ASSERT_TRUE(first.record(1, {{"index", 1}, {"v", 10}}).is_ok());
  }  // interrupted: never finished
  FrameStatsFile same(dir.path(), header, true);
  ASSERT_TRUE(same.previous(1).has_value());
  EXPECT_EQ((*same.previous(1))["v"], 10);
  EXPECT_FALSE(same.previous(0).has_value());
  EXPECT_TRUE(same.resume_note().empty());
  FrameStatsFile fresh(dir.path(), header, false);
  EXPECT_FALSE(fresh.previous(1).has_value());
  FrameStatsFile other(dir.path(), {{"command", "test"}, {"options", {{"size", 4}}}}, true);
  EXPECT_FALSE(other.previous(1).has_value());
  EXPECT_NE(other.resume_note().find("other options"), std::string::npos) << other.resume_note();
}

TEST(FrameStatsFile, AllExistNeedsEveryFile) {
  TempDir dir;
  ASSERT_TRUE(write_json(dir / "a.json", nlohmann::json::object()).is_ok());
  EXPECT_TRUE(all_exist({dir / "a.json"}));
  EXPECT_FALSE(all_exist({dir / "a.json", dir / "b.json"}));
}

}  // namespace
}  // namespace gvkit::tools
