#include "gvkit/core/json_io.hpp"

#include "gvkit/core/atomic_file.hpp"

namespace gvkit {

Result<nlohmann::json> read_json(const std::filesystem::path& path) {
  GVKIT_ASSIGN_OR_RETURN(std::string text, read_file(path));
  nlohmann::json value = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (value.is_discarded()) return corrupt_data(path.string() + ": not valid JSON");
  return value;
}

Status write_json(const std::filesystem::path& path, const nlohmann::json& value, int indent) {
  return write_file_atomically(path, value.dump(indent) + "\n");
}

}  // namespace gvkit
