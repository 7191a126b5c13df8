#pragma once
// Landmarks as JSON: {"points_px": [[x, y], ...], "points_mm": [[x, y, z], ...]}, 68 entries
// each (either list may be absent or empty). An absent jaw point (0-16, landmarks from a 51-point
// set) is written and read as null; any other point must be finite. Written atomically. Files of
// other tools: landmark_points_io.hpp.

#include <filesystem>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit {

Result<FaceLandmarks> read_face_landmarks(const std::filesystem::path& path);
Status write_face_landmarks(const std::filesystem::path& path, const FaceLandmarks& landmarks);

}  // namespace gvkit
