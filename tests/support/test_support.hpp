#pragma once
// Helpers shared by gvkit tests: temporary folders, the shared data folder, running the CLI.

#include <filesystem>
#include <string>

namespace gvkit::testing {

// A fresh folder under the system temp dir, removed when the object goes.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// ../shared/data (from GVKIT_SHARED_DATA); empty path when the folder is absent.
std::filesystem::path shared_data_dir();

// Skips the current test with a message when ../shared/data is absent.
#define GVKIT_REQUIRE_SHARED_DATA(dir)                                   \
  const std::filesystem::path dir = ::gvkit::testing::shared_data_dir(); \
  if (dir.empty()) GTEST_SKIP() << "../shared/data is absent; this test needs it"

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};
// Runs the gvkit binary (GVKIT_BINARY) with the given argument string.
CommandResult run_gvkit(const std::string& arguments);

// Whether text contains part (for checking error messages and command output).
inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace gvkit::testing
