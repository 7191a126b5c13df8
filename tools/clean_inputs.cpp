#include "clean_inputs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

namespace gvkit::tools {
namespace fs = std::filesystem;

Result<double> mesh_scale(const std::string& units, double scale) {
  if (!units.empty() && scale != 0)
    return invalid_argument("--units and --scale say the same thing: give one");
  if (scale != 0) {
    if (!(scale > 0 && std::isfinite(scale)))
      return invalid_argument("--scale must be > 0, got " + std::to_string(scale));
    return scale;
  }
  if (units.empty() || units == "mm") return 1.0;
  if (units == "cm") return 10.0;
  if (units == "m") return 1000.0;
  return invalid_argument("--units must be mm, cm or m, got " + units);
}

Status check_face_size(const Mesh& mesh, const std::string& name) {
  Mesh::Point lo(std::numeric_limits<double>::infinity()), hi(-lo);
  for (auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  const double size = mesh.n_vertices() > 0 ? (hi - lo).norm() : 0.0;
  if (size >= kMinFaceMm && size <= kMaxFaceMm) return Status::ok();
  std::string hint;
  for (const auto& [units, factor] :
       {std::pair<const char*, double>{"cm", 10.0}, {"m", 1000.0}, {"mm", 1.0}}) {
    const double scaled = size * factor;
    if (scaled >= kMinFaceMm && scaled <= kMaxFaceMm) {
      hint = std::string(": is it in ") + (factor == 10.0 ? "centimetres" : "metres") +
             "? Then say --units " + units;
      break;
    }
  }
  if (hint.empty()) hint = ": give its units with --units mm|cm|m or --scale MM_PER_UNIT";
  char text[160];
  std::snprintf(text, sizeof text, "the mesh is %.3g units across; a face or head is %.0f-%.0f mm",
                size, kMinFaceMm, kMaxFaceMm);
  return failed_precondition(name + ": " + text + hint + " (--units mm takes it as it is)");
}

std::optional<fs::path> find_landmark_file(const fs::path& mesh_path, const fs::path& dir) {
  const std::string stem = mesh_path.stem().string();
  const std::vector<std::string> in_dir = {
      ".landmarks.json", ".json", ".npy", ".txt", ".csv", ".pts"};
  const std::vector<std::string> beside = {".landmarks.json", ".landmarks.npy", ".landmarks.txt",
                                           ".landmarks.csv",  ".landmarks.pts", ".pts"};
  const fs::path folder = dir.empty() ? mesh_path.parent_path() : dir;
  std::error_code ec;
  for (const auto& suffix : dir.empty() ? beside : in_dir) {
    const fs::path candidate = folder / (stem + suffix);
    if (fs::is_regular_file(candidate, ec)) return candidate;
  }
  return std::nullopt;
}

nlohmann::json soup_json(const TriangleSoup& soup, double scale) {
  nlohmann::json j = {{"points", soup.points.size()},
                      {"polygons", soup.polygons},
                      {"split_polygons", soup.split_polygons},
                      {"triangles", soup.triangles.size()},
                      {"mm_per_unit", scale},
                      {"vertex_colours", !soup.colors.empty()},
                      {"notes", soup.notes}};
  nlohmann::json textures = nlohmann::json::array();
  if (soup.has_texture())
    for (const auto& p : soup.texture_paths) textures.push_back(p.filename().string());
  j["textures"] = textures;
  return j;
}

nlohmann::json repair_json(const facemap::MeshRepairReport& r) {
  return {{"non_finite_faces", r.non_finite_faces},
          {"degenerate_faces", r.degenerate_faces},
          {"duplicate_faces", r.duplicate_faces},
          {"non_manifold_edges", r.non_manifold_edges},
          {"non_manifold_faces", r.non_manifold_faces},
          {"flipped_faces", r.flipped_faces},
          {"components", r.components},
          {"removed_component_faces", r.removed_component_faces},
          {"kept_area_share", r.kept_area_share},
          {"removed_vertices", r.removed_vertices},
          {"summary", r.summary()}};
}

nlohmann::json input_fingerprint(const std::vector<fs::path>& files) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& f : files) {
    std::error_code ec;
    nlohmann::json j = {{"file", f.string()}};
    const auto size = fs::file_size(f, ec);
    if (ec) {
      j["absent"] = true;
    } else {
      j["bytes"] = size;
      const auto time = fs::last_write_time(f, ec);
      j["modified_ns"] =
          ec ? 0
             : std::chrono::duration_cast<std::chrono::nanoseconds>(time.time_since_epoch())
                   .count();
    }
    out.push_back(j);
  }
  return out;
}

}  // namespace gvkit::tools
