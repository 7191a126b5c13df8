#include "gvkit/core/frame_files.hpp"

#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::TempDir;

TEST(FrameFiles, NamesHaveSixDigits) {
  EXPECT_EQ(frame_file_name(42, ".exr"), "frame_000042.exr");
  EXPECT_EQ(frame_file_name(0, ".landmarks.json"), "frame_000000.landmarks.json");
}

TEST(FrameFiles, ListsOnlyMatchingFilesInIndexOrder) {
  TempDir dir;
  for (int i : {3, 1, 10})
    ASSERT_TRUE(write_file_atomically(frame_path(dir.path(), i, ".exr"), "x").is_ok());
  ASSERT_TRUE(write_file_atomically(dir / "frame_000002.ply", "x").is_ok());
  ASSERT_TRUE(write_file_atomically(dir / "frame_00002.exr", "x").is_ok());
  ASSERT_TRUE(write_file_atomically(dir / "stats.json", "{}").is_ok());
  auto files = list_frame_files(dir.path(), ".exr");
  ASSERT_TRUE(files.is_ok());
  ASSERT_EQ(files->size(), 3u);
  EXPECT_EQ((*files)[0].index, 1);
  EXPECT_EQ((*files)[2].index, 10);
  EXPECT_EQ(list_frame_files(dir / "none", ".exr").status().code(), StatusCode::kNotFound);
}

TEST(FrameFiles, EnsureDirectoryRefusesAFile) {
  TempDir dir;
  EXPECT_TRUE(ensure_directory(dir / "a" / "b").is_ok());
  ASSERT_TRUE(write_file_atomically(dir / "f", "x").is_ok());
  EXPECT_FALSE(ensure_directory(dir / "f").is_ok());
}

}  // namespace
}  // namespace gvkit
