#pragma once
// The inputs of `gvkit facemap clean` besides the frames themselves: mesh units, the plausibility
// of a mesh's size, where a frame's landmark file is, and the figures of what was read and
// repaired for stats.json.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/core/triangle_soup.hpp"
#include "gvkit/facemap/mesh_repair.hpp"

namespace gvkit::tools {

// Millimetres per mesh file unit from --units (mm, cm, m; empty: not given) and --scale (0: not
// given). Fails when both are given or the units are unknown.
Result<double> mesh_scale(const std::string& units, double scale);

// A face or head scan in mm is between kMinFaceMm and kMaxFaceMm across (bounding-box diagonal).
constexpr double kMinFaceMm = 60.0, kMaxFaceMm = 1500.0;

// Fails naming `name` when the mesh (mm) is too small or too large for a face, suggesting the
// --units that would make it one. Meshes whose units were given are not checked.
Status check_face_size(const Mesh& mesh, const std::string& name);

// The landmark file of the frame whose mesh is `mesh_path` (stem S): in `dir` when given (a
// folder of landmark files: S.landmarks.json, S.json, S.npy, S.txt, S.csv, S.pts), else beside
// the mesh (S.landmarks.json, S.landmarks.npy, S.landmarks.txt, S.landmarks.csv,
// S.landmarks.pts, S.pts). nullopt when there is none.
std::optional<std::filesystem::path> find_landmark_file(const std::filesystem::path& mesh_path,
                                                        const std::filesystem::path& dir = {});

// What a mesh file held: points, polygons, triangles, split polygons, texture, notes, scale.
nlohmann::json soup_json(const TriangleSoup& soup, double scale);
// Every count of a repair report, and its summary.
nlohmann::json repair_json(const facemap::MeshRepairReport& report);

// Size and modification time of each file (absent files as such): a failed frame of an earlier
// run is kept on --resume only when its inputs are unchanged.
nlohmann::json input_fingerprint(const std::vector<std::filesystem::path>& files);

}  // namespace gvkit::tools
