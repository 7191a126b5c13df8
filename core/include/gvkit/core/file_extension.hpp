#pragma once
// File-name extensions compared without regard to case (ASCII).

#include <filesystem>
#include <string>

namespace gvkit {

// `text` with the ASCII letters A-Z turned into a-z; other bytes unchanged.
std::string ascii_lower(std::string text);

// The extension of `path` with its leading dot, lower-cased: "scan.PLY" -> ".ply"; "" when the
// name has none.
std::string lower_extension(const std::filesystem::path& path);

}  // namespace gvkit
