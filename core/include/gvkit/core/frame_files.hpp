#pragma once
// The per-frame file naming shared by every command: frame_NNNNNN.<ext> (six digits, from 0).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "gvkit/core/status.hpp"

namespace gvkit {

// "frame_000042.exr" for (42, ".exr"); suffix may carry more, e.g. ".landmarks.json".
std::string frame_file_name(int64_t index, const std::string& suffix);
std::filesystem::path frame_path(const std::filesystem::path& dir, int64_t index,
                                 const std::string& suffix);

struct FrameFile {
  int64_t index;
  std::filesystem::path path;
};
// The frame_NNNNNN<suffix> files of dir, sorted by index. Fails when dir is missing or not a
// folder; an empty list is not an error.
Result<std::vector<FrameFile>> list_frame_files(const std::filesystem::path& dir,
                                                const std::string& suffix);

// Creates dir (and parents). Fails naming dir when it exists as a file or cannot be created.
Status ensure_directory(const std::filesystem::path& dir);

}  // namespace gvkit
