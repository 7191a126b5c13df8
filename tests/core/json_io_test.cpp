#include "gvkit/core/json_io.hpp"

#include <gtest/gtest.h>

#include "gvkit/core/atomic_file.hpp"
#include "support/test_support.hpp"

namespace gvkit {
namespace {
using testing::TempDir;

TEST(JsonIo, RoundTripAndAtomicReplace) {
  TempDir dir;
  nlohmann::json value = {{"frames", 60}, {"fps", 30.0}, {"name", "take3"}};
  ASSERT_TRUE(write_json(dir / "s.json", value).is_ok());
  auto back = read_json(dir / "s.json");
  ASSERT_TRUE(back.is_ok());
  EXPECT_EQ(*back, value);
  value["frames"] = 61;
  ASSERT_TRUE(write_json(dir / "s.json", value).is_ok());
  EXPECT_EQ((*read_json(dir / "s.json"))["frames"], 61);
  // Only the target file is left: no temporary files.
  int files = 0;
  for (auto& e : std::filesystem::directory_iterator(dir.path())) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
}

TEST(JsonIo, InvalidJsonIsNamed) {
  TempDir dir;
  ASSERT_TRUE(write_file_atomically(dir / "bad.json", "{\"frames\": 6").is_ok());
  auto bad = read_json(dir / "bad.json");
  EXPECT_EQ(bad.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(bad.status().message().find("bad.json"), std::string::npos);
  EXPECT_EQ(read_json(dir / "none.json").status().code(), StatusCode::kNotFound);
  EXPECT_EQ(read_json(dir.path()).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace gvkit
