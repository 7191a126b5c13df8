#pragma once
// The gvkit version, from the CMake project version.

namespace gvkit {
const char* version_string();  // "0.1.0"
}  // namespace gvkit
