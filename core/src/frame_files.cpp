#include "gvkit/core/frame_files.hpp"

#include <algorithm>
#include <cstdio>
#include <system_error>

namespace gvkit {
namespace fs = std::filesystem;

std::string frame_file_name(int64_t index, const std::string& suffix) {
  char digits[32];
  std::snprintf(digits, sizeof digits, "frame_%06lld", static_cast<long long>(index));
  return digits + suffix;
}

fs::path frame_path(const fs::path& dir, int64_t index, const std::string& suffix) {
  return dir / frame_file_name(index, suffix);
}

Result<std::vector<FrameFile>> list_frame_files(const fs::path& dir, const std::string& suffix) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) return not_found(dir.string() + ": no such folder");
  if (!fs::is_directory(dir, ec)) return invalid_argument(dir.string() + ": not a folder");
  std::vector<FrameFile> files;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() != 12 + suffix.size() || name.rfind("frame_", 0) != 0 ||
        name.compare(12, std::string::npos, suffix) != 0)
      continue;
    const std::string digits = name.substr(6, 6);
    if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
      continue;
    files.push_back({std::stoll(digits), entry.path()});
  }
  if (ec) return io_error(dir.string() + ": cannot list: " + ec.message());
  std::sort(files.begin(), files.end(),
            [](const FrameFile& a, const FrameFile& b) { return a.index < b.index; });
  return files;
}

Status ensure_directory(const fs::path& dir) {
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec))
      return invalid_argument(dir.string() + ": exists and is not a folder");
    return Status::ok();
  }
  fs::create_directories(dir, ec);
  if (ec) return io_error(dir.string() + ": cannot create folder: " + ec.message());
  return Status::ok();
}

}  // namespace gvkit
