#include "gvkit/core/face_landmarks_io.hpp"

#include <algorithm>
#include <cmath>

#include "gvkit/core/json_io.hpp"

namespace gvkit {

Result<FaceLandmarks> read_face_landmarks(const std::filesystem::path& path) {
  GVKIT_ASSIGN_OR_RETURN(nlohmann::json json, read_json(path));
  FaceLandmarks landmarks;
  auto read_list = [&](const char* key, int dims, auto&& add) -> Status {
    if (!json.contains(key) || json[key].is_null()) return Status::ok();
    const auto& list = json[key];
    if (!list.is_array() || !(list.empty() || list.size() == FaceLandmarks::kCount))
      return corrupt_data(path.string() + ": " + key + " must list 68 points");
    for (size_t i = 0; i < list.size(); ++i) {
      const auto& p = list[i];
      // An absent jaw point (landmarks from a 51-point set) is null, or a list of nulls.
      const bool absent = p.is_null() || (p.is_array() && !p.empty() &&
                                          std::all_of(p.begin(), p.end(),
                                                      [](const auto& x) { return x.is_null(); }));
      if (absent && i < FaceLandmarks::kJawCount) {
        const double nan[3] = {NAN, NAN, NAN};
        add(nan);
        continue;
      }
      if (!p.is_array() || static_cast<int>(p.size()) != dims)
        return corrupt_data(path.string() + ": " + key + "[" + std::to_string(i) + "] must have " +
                            std::to_string(dims) + " numbers");
      double v[3] = {0, 0, 0};
      for (int d = 0; d < dims; ++d) {
        if (!p[d].is_number() || !std::isfinite(p[d].get<double>()))
          return corrupt_data(path.string() + ": " + key + "[" + std::to_string(i) +
                              "] is not finite");
        v[d] = p[d].get<double>();
      }
      add(v);
    }
    return Status::ok();
  };
  GVKIT_RETURN_IF_ERROR(read_list("points_px", 2, [&](const double* v) {
    landmarks.points_px.emplace_back(static_cast<float>(v[0]), static_cast<float>(v[1]));
  }));
  GVKIT_RETURN_IF_ERROR(read_list("points_mm", 3, [&](const double* v) {
    landmarks.points_mm.emplace_back(static_cast<float>(v[0]), static_cast<float>(v[1]),
                                     static_cast<float>(v[2]));
  }));
  return landmarks;
}

Status write_face_landmarks(const std::filesystem::path& path, const FaceLandmarks& landmarks) {
  nlohmann::json json = {{"points_px", nlohmann::json::array()},
                         {"points_mm", nlohmann::json::array()}};
  for (const auto& p : landmarks.points_px) json["points_px"].push_back({p.x, p.y});
  for (const auto& p : landmarks.points_mm) json["points_mm"].push_back({p[0], p[1], p[2]});
  return write_json(path, json, 1);
}

}  // namespace gvkit
