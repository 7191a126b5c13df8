#include "gvkit/core/ict_face_model.hpp"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <string_view>

#include "gvkit/core/json_io.hpp"

namespace gvkit {
namespace fs = std::filesystem;
namespace {

constexpr double kMmPerCm = 10.0;
const char* const kNeutralFile = "generic_neutral_mesh.obj";

struct ObjData {
  std::vector<cv::Vec3d> positions;
  std::vector<cv::Vec2f> texcoords;
  std::vector<IctFaceModel::Polygon> polygons;
};

bool parse_doubles(std::string_view text, double* out, int count) {
  const char* p = text.data();
  const char* end = text.data() + text.size();
  for (int i = 0; i < count; ++i) {
    while (p < end && (*p == ' ' || *p == '\t')) ++p;
    auto [next, ec] = std::from_chars(p, end, out[i]);
    if (ec != std::errc()) return false;
    p = next;
  }
  return true;
}

// A minimal OBJ reader that keeps the file's vertex order exactly (the blendshapes rely on it).
Result<ObjData> read_obj(const fs::path& path, bool with_faces) {
  std::ifstream in(path);
  if (!in) return not_found(path.string() + ": cannot open");
  ObjData data;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.size() < 2) continue;
    const std::string_view rest(line.data() + 2, line.size() - 2);
    if (line[0] == 'v' && line[1] == ' ') {
      double xyz[3];
      if (!parse_doubles(rest, xyz, 3))
        return corrupt_data(path.string() + ": line " + std::to_string(line_number) +
                            ": bad vertex");
      data.positions.emplace_back(xyz[0] * kMmPerCm, xyz[1] * kMmPerCm, xyz[2] * kMmPerCm);
    } else if (with_faces && line[0] == 'v' && line[1] == 't') {
      double uv[2];
      if (!parse_doubles(std::string_view(line.data() + 3, line.size() - 3), uv, 2))
        return corrupt_data(path.string() + ": line " + std::to_string(line_number) +
                            ": bad texcoord");
      data.texcoords.emplace_back(static_cast<float>(uv[0]), static_cast<float>(uv[1]));
    } else if (with_faces && line[0] == 'f' && line[1] == ' ') {
      IctFaceModel::Polygon polygon;
      size_t pos = 2;
      while (pos < line.size()) {
        while (pos < line.size() && line[pos] == ' ') ++pos;
        if (pos >= line.size()) break;
        size_t end = line.find(' ', pos);
        if (end == std::string::npos) end = line.size();
        const std::string token = line.substr(pos, end - pos);
        pos = end;
        int v = 0, t = 0;
        const size_t slash = token.find('/');
        auto r = std::from_chars(token.data(), token.data() + std::min(slash, token.size()), v);
        if (r.ec != std::errc() || v <= 0)
          return corrupt_data(path.string() + ": line " + std::to_string(line_number) +
                              ": bad face");
        if (slash != std::string::npos)
          std::from_chars(token.data() + slash + 1, token.data() + token.size(), t);
        polygon.push_back({v - 1, t > 0 ? t - 1 : -1});
      }
      if (polygon.size() < 3)
        return corrupt_data(path.string() + ": line " + std::to_string(line_number) +
                            ": face with < 3 corners");
      data.polygons.push_back(std::move(polygon));
    }
  }
  for (const auto& polygon : data.polygons)
    for (const auto& c : polygon)
      if (c.vertex >= static_cast<int>(data.positions.size()) ||
          c.texcoord >= static_cast<int>(data.texcoords.size()))
        return corrupt_data(path.string() + ": face index out of range");
  return data;
}

}  // namespace

Result<IctFaceModel> IctFaceModel::load(const fs::path& dir,
                                        const std::vector<std::string>& expressions) {
  IctFaceModel model;
  GVKIT_ASSIGN_OR_RETURN(ObjData neutral, read_obj(dir / kNeutralFile, true));
  if (neutral.positions.size() != kVertexCount)
    return corrupt_data((dir / kNeutralFile).string() + ": expected " +
                        std::to_string(kVertexCount) + " vertices, found " +
                        std::to_string(neutral.positions.size()));
  model.neutral_mm_ = std::move(neutral.positions);
  model.polygons_ = std::move(neutral.polygons);
  model.texcoords_ = std::move(neutral.texcoords);

  GVKIT_ASSIGN_OR_RETURN(nlohmann::json indices, read_json(dir / "vertex_indices.json"));
  const auto& landmarks = indices["idx_to_landmark_verts"];
  if (!landmarks.is_array() || landmarks.size() != 68)
    return corrupt_data((dir / "vertex_indices.json").string() +
                        ": idx_to_landmark_verts must list 68 vertices");
  for (int i = 0; i < 68; ++i) {
    if (!landmarks[i].is_number_integer() || landmarks[i].get<int>() < 0 ||
        landmarks[i].get<int>() >= kVertexCount)
      return corrupt_data((dir / "vertex_indices.json").string() + ": bad landmark vertex " +
                          std::to_string(i));
    model.landmark_vertices_[i] = landmarks[i].get<int>();
  }

  std::vector<std::string> names = expressions;
  if (names.empty()) {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      const std::string stem = entry.path().stem().string();
      if (entry.path().extension() == ".obj" && stem != "generic_neutral_mesh" &&
          stem.rfind("identity", 0) != 0)
        names.push_back(stem);
    }
    std::sort(names.begin(), names.end());
  }
  for (const auto& name : names) {
    const fs::path path = dir / (name + ".obj");
    GVKIT_ASSIGN_OR_RETURN(ObjData shape, read_obj(path, false));
    if (shape.positions.size() != kVertexCount)
      return corrupt_data(path.string() + ": expected " + std::to_string(kVertexCount) +
                          " vertices");
    for (size_t v = 0; v < shape.positions.size(); ++v) shape.positions[v] -= model.neutral_mm_[v];
    model.deltas_mm_[name] = std::move(shape.positions);
  }
  return model;
}

std::vector<std::string> IctFaceModel::expression_names() const {
  std::vector<std::string> names;
  for (const auto& [name, delta] : deltas_mm_) names.push_back(name);
  return names;
}

std::vector<cv::Vec3d> IctFaceModel::evaluate(const std::map<std::string, double>& weights) const {
  std::vector<cv::Vec3d> positions = neutral_mm_;
  for (const auto& [name, weight] : weights) {
    auto it = deltas_mm_.find(name);
    GVKIT_CHECK(it != deltas_mm_.end(), "unknown ICT expression " + name);
    if (weight == 0) continue;
    for (size_t v = 0; v < positions.size(); ++v) positions[v] += weight * it->second[v];
  }
  return positions;
}

IctRegion IctFaceModel::region_of(int v) {
  if (v < 9409) return IctRegion::kFace;
  if (v < 11248) return IctRegion::kHeadAndNeck;
  if (v < 13294) return IctRegion::kMouthSocket;
  if (v < 14062) return IctRegion::kEyeSocket;
  if (v < 17039) return IctRegion::kGumsAndTongue;
  if (v < 21451) return IctRegion::kTeeth;
  if (v < 22221 || (v >= 23021 && v < 23791)) return IctRegion::kSclera;
  if (v < 24591) return IctRegion::kIris;
  if (v < 25351) return IctRegion::kEyeExtras;
  return IctRegion::kEyelashes;
}

Mesh IctFaceModel::build_mesh(const std::vector<cv::Vec3d>& positions_mm,
                              const std::vector<char>& keep,
                              std::vector<int>* original_index) const {
  GVKIT_CHECK(positions_mm.size() == neutral_mm_.size(),
              "positions must have one entry per vertex");
  Mesh mesh;
  std::vector<Mesh::VertexHandle> handle(positions_mm.size());
  if (original_index) original_index->clear();
  // Only vertices used by a kept polygon become mesh vertices.
  std::vector<char> used(positions_mm.size(), 0);
  for (const auto& polygon : polygons_) {
    bool all = true;
    for (const auto& c : polygon) all = all && keep[c.vertex];
    if (all)
      for (const auto& c : polygon) used[c.vertex] = 1;
  }
  for (size_t v = 0; v < positions_mm.size(); ++v) {
    if (!used[v]) continue;
    const auto& p = positions_mm[v];
    handle[v] = mesh.add_vertex(Mesh::Point(p[0], p[1], p[2]));
    if (original_index) original_index->push_back(static_cast<int>(v));
  }
  auto point = [&](int v) { return cv::Vec3d(positions_mm[v]); };
  for (const auto& polygon : polygons_) {
    bool all = true;
    for (const auto& c : polygon) all = all && keep[c.vertex];
    if (!all) continue;
    if (polygon.size() == 4) {
      const int a = polygon[0].vertex, b = polygon[1].vertex, c = polygon[2].vertex,
                d = polygon[3].vertex;
      if (cv::norm(point(a) - point(c)) <= cv::norm(point(b) - point(d))) {
        mesh.add_face(handle[a], handle[b], handle[c]);
        mesh.add_face(handle[a], handle[c], handle[d]);
      } else {
        mesh.add_face(handle[a], handle[b], handle[d]);
        mesh.add_face(handle[b], handle[c], handle[d]);
      }
    } else {
      for (size_t k = 1; k + 1 < polygon.size(); ++k)
        mesh.add_face(handle[polygon[0].vertex], handle[polygon[k].vertex],
                      handle[polygon[k + 1].vertex]);
    }
  }
  return mesh;
}

}  // namespace gvkit
