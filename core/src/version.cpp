#include "gvkit/core/version.hpp"

namespace gvkit {
const char* version_string() { return GVKIT_VERSION; }
}  // namespace gvkit
