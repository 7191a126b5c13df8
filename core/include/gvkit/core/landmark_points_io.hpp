#pragma once
// Landmark files made by other tools (or by hand), in the iBUG 68-point numbering
// (face_landmarks.hpp) or its 51-point subset without the jaw (iBUG points 17-67, as many
// trackers give). The points are either 2-D image pixels (x right, y down) or 3-D surface points
// in the frame and units of the mesh they belong to.
//
// Formats, by extension:
//   .npy         a NumPy array of shape (68, 2), (68, 3), (51, 2) or (51, 3) (leading axes of
//                length 1 are allowed: (1, 68, 2)), any numeric dtype;
//   .txt .csv .pts  one point per row, 2 or 3 numbers separated by spaces, tabs, commas or
//                semicolons; '#' starts a comment; lines of text before the first row (a CSV
//                header, the iBUG .pts "version: 1", "n_points: 68", "{") and a closing "}" are
//                skipped;
//   .json        a list of [x, y] or [x, y, z] lists, or an object holding one under "landmarks"
//                or "points", or gvkit's own {"points_px": [...], "points_mm": [...]}
//                (face_landmarks_io.hpp; there the jaw points 0-16 may be null).
//
// Every point must be finite; rows must all have the same number of coordinates; the count must
// be 51 or 68. Failures name the file and what is wrong.

#include <filesystem>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit {

struct LandmarkPoints {
  int dims = 0;        // 2: image pixels; 3: surface points
  int file_count = 0;  // 51 or 68, as in the file
  // 68 points in the 68-point numbering; absent ones (the jaw of a 51-point file) are NaN. 2-D
  // points have z = 0.
  std::vector<cv::Vec3d> points;
};

// `dims` chooses between gvkit's points_px (2) and points_mm (3) when a gvkit JSON has both
// (0: 3-D when present); other files give what they hold.
Result<LandmarkPoints> read_landmark_points(const std::filesystem::path& path, int dims = 0);

// True for the extensions read_landmark_points reads (.npy .txt .csv .pts .json).
bool is_landmark_file(const std::filesystem::path& path);

// The points as FaceLandmarks: 3-D points (times `scale`) as points_mm, 2-D ones as points_px;
// absent points stay NaN.
FaceLandmarks to_face_landmarks(const LandmarkPoints& points, double scale = 1.0);

}  // namespace gvkit
