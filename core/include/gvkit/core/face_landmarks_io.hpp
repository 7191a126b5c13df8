#pragma once
// Landmarks as JSON: {"points_px": [[x, y], ...], "points_mm": [[x, y, z], ...]}, 68 entries
// each (either list may be absent or empty). Written atomically.

#include <filesystem>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit {

Result<FaceLandmarks> read_face_landmarks(const std::filesystem::path& path);
Status write_face_landmarks(const std::filesystem::path& path, const FaceLandmarks& landmarks);

}  // namespace gvkit
