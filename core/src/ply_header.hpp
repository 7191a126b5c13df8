#pragma once
// Internal: a structural check of a PLY file before OpenMesh parses it. OpenMesh trusts the
// header (a missing end_header makes it allocate without bound; a truncated body reads as a
// shorter mesh), so the header is parsed here and the body size checked against it.

#include <filesystem>

#include "gvkit/core/status.hpp"

namespace gvkit::detail {

// Ok when the file starts with "ply", has an end_header within the first 64 KiB, declares sane
// element counts, and its body is long enough for them (binary: byte count with the minimum
// list length; ASCII: line count). Fails naming the file and what is wrong.
Status check_ply_structure(const std::filesystem::path& path);

}  // namespace gvkit::detail
