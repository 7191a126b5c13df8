#pragma once
// JSON files through nlohmann-json. Writes are atomic (temp file + fsync + rename), so a reader
// sees either the old or the new file, never a partial one.

#include <filesystem>

#include <nlohmann/json.hpp>

#include "gvkit/core/status.hpp"

namespace gvkit {

Result<nlohmann::json> read_json(const std::filesystem::path& path);
Status write_json(const std::filesystem::path& path, const nlohmann::json& value, int indent = 2);

}  // namespace gvkit
