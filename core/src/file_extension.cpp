#include "gvkit/core/file_extension.hpp"

#include <algorithm>
#include <cctype>

namespace gvkit {

std::string ascii_lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

std::string lower_extension(const std::filesystem::path& path) {
  return ascii_lower(path.extension().string());
}

}  // namespace gvkit
