#pragma once
// Crash-safe whole-file writes: write to "<path>.tmp-<pid>", fsync, rename over <path>, fsync the
// directory. After a crash at any point, <path> is either the old content or the new one.

#include <filesystem>
#include <functional>
#include <string_view>

#include "gvkit/core/status.hpp"

namespace gvkit {

// Writes bytes to path atomically. Fails (naming the path) on I/O errors, e.g. a full disk; the
// temporary file is removed on failure.
Status write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

// For writers that need a file name (OpenEXR, OpenCV, OpenMesh): calls write(temp_path), then
// fsyncs and renames temp_path over path. write's Status is returned as is on failure.
Status write_via_temp_file(const std::filesystem::path& path,
                           const std::function<Status(const std::filesystem::path&)>& write);

// Reads a whole file. Fails naming the path when it is missing or unreadable.
Result<std::string> read_file(const std::filesystem::path& path);

}  // namespace gvkit
