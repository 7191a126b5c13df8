#include "gvkit/core/landmark_points_io.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string>

#include "gvkit/core/atomic_file.hpp"
#include "gvkit/core/file_extension.hpp"
#include "gvkit/core/json_io.hpp"
#include "gvkit/core/npy_io.hpp"

namespace gvkit {
namespace fs = std::filesystem;
namespace {

constexpr int kJawPoints = 17;  // points 0-16; a 51-point set starts at 17

// Rows of `dims` numbers (as read, NaN for an absent gvkit jaw point) -> LandmarkPoints.
Result<LandmarkPoints> from_rows(const std::string& name, const std::vector<cv::Vec3d>& rows,
                                 int dims, const std::vector<char>& absent = {}) {
  const int n = static_cast<int>(rows.size());
  if (n != FaceLandmarks::kCount && n != FaceLandmarks::kCount - kJawPoints)
    return corrupt_data(name + ": " + std::to_string(n) +
                        " points; 68 (iBUG) or 51 (iBUG without the jaw) expected");
  if (dims != 2 && dims != 3)
    return corrupt_data(name + ": points have " + std::to_string(dims) +
                        " coordinates; 2 (image pixels) or 3 (surface points) expected");
  LandmarkPoints out;
  out.dims = dims;
  out.file_count = n;
  const int offset = FaceLandmarks::kCount - n;
  out.points.assign(FaceLandmarks::kCount, cv::Vec3d(NAN, NAN, NAN));
  for (int i = 0; i < n; ++i) {
    const bool may_be_absent = !absent.empty() && absent[i] && i + offset < kJawPoints;
    if (!absent.empty() && absent[i] && !may_be_absent)
      return corrupt_data(name + ": point " + std::to_string(i + offset) +
                          " is missing (only the jaw, 0-16, may be)");
    if (may_be_absent) continue;
    for (int k = 0; k < dims; ++k)
      if (!std::isfinite(rows[i][k]))
        return corrupt_data(name + ": point " + std::to_string(i) + " is not finite");
    out.points[i + offset] = cv::Vec3d(rows[i][0], rows[i][1], dims == 3 ? rows[i][2] : 0.0);
  }
  return out;
}

Result<LandmarkPoints> read_npy_points(const fs::path& path) {
  const std::string name = path.string();
  GVKIT_ASSIGN_OR_RETURN(const NpyArray array, read_npy(path));
  std::vector<size_t> shape;
  for (size_t i = 0; i < array.shape.size(); ++i)
    if (!(array.shape[i] == 1 && i + 2 < array.shape.size())) shape.push_back(array.shape[i]);
  auto shape_text = [&] {
    std::string s = "(";
    for (size_t i = 0; i < array.shape.size(); ++i)
      s += (i ? ", " : "") + std::to_string(array.shape[i]);
    return s + (array.shape.size() == 1 ? ",)" : ")");
  };
  if (shape.size() != 2 || (shape[1] != 2 && shape[1] != 3))
    return corrupt_data(name + ": array of shape " + shape_text() +
                        "; (68, 2), (68, 3), (51, 2) or (51, 3) expected");
  std::vector<cv::Vec3d> rows(shape[0]);
  for (size_t i = 0; i < shape[0]; ++i)
    for (size_t k = 0; k < shape[1]; ++k) rows[i][k] = array.values[i * shape[1] + k];
  return from_rows(name, rows, static_cast<int>(shape[1]));
}

bool parse_number(const std::string& token, double* value) {
  char* end = nullptr;
  *value = std::strtod(token.c_str(), &end);
  return !token.empty() && end == token.c_str() + token.size();
}

Result<LandmarkPoints> read_text_points(const fs::path& path) {
  const std::string name = path.string();
  GVKIT_ASSIGN_OR_RETURN(const std::string text, read_file(path));
  std::vector<cv::Vec3d> rows;
  int dims = 0, line_number = 0;
  bool closed = false;
  size_t at = 0;
  while (at < text.size()) {
    size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(at, end - at);
    at = end + 1;
    ++line_number;
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    for (char& c : line)
      if (c == ',' || c == ';' || c == '\t' || c == '\r') c = ' ';
    std::vector<std::string> tokens;
    for (size_t i = 0; i < line.size();) {
      while (i < line.size() && line[i] == ' ') ++i;
      const size_t start = i;
      while (i < line.size() && line[i] != ' ') ++i;
      if (i > start) tokens.push_back(line.substr(start, i - start));
    }
    if (tokens.empty()) continue;
    const std::string where = name + ": line " + std::to_string(line_number);
    double first;
    if (!parse_number(tokens[0], &first)) {
      if (tokens.size() == 1 && tokens[0] == "}") {
        closed = true;
        continue;
      }
      if (rows.empty()) continue;  // a header line
      return corrupt_data(where + ": '" + tokens[0] + "' is not a number");
    }
    if (closed) return corrupt_data(where + ": a point after the closing '}'");
    if (tokens.size() != 2 && tokens.size() != 3)
      return corrupt_data(where + ": " + std::to_string(tokens.size()) +
                          " numbers; 2 or 3 per row expected");
    if (dims == 0) dims = static_cast<int>(tokens.size());
    if (static_cast<int>(tokens.size()) != dims)
      return corrupt_data(where + ": " + std::to_string(tokens.size()) + " numbers after rows of " +
                          std::to_string(dims));
    cv::Vec3d row(0, 0, 0);
    for (int k = 0; k < dims; ++k)
      if (!parse_number(tokens[k], &row[k]))
        return corrupt_data(where + ": '" + tokens[k] + "' is not a number");
    rows.push_back(row);
  }
  if (rows.empty()) return corrupt_data(name + ": no points");
  return from_rows(name, rows, dims);
}

// One JSON list of points; null entries (gvkit's absent jaw points) only when allowed.
Result<LandmarkPoints> json_list_points(const std::string& name, const nlohmann::json& list,
                                        bool allow_null) {
  if (!list.is_array()) return corrupt_data(name + ": the points are not a list");
  std::vector<cv::Vec3d> rows;
  std::vector<char> absent;
  int dims = 0;
  for (size_t i = 0; i < list.size(); ++i) {
    const auto& p = list[i];
    const std::string where = name + ": point " + std::to_string(i);
    const bool null_point =
        p.is_null() || (p.is_array() &&
                        std::all_of(p.begin(), p.end(), [](const auto& x) { return x.is_null(); }));
    if (null_point && allow_null) {
      rows.emplace_back(NAN, NAN, NAN);
      absent.push_back(1);
      continue;
    }
    if (!p.is_array() || (p.size() != 2 && p.size() != 3))
      return corrupt_data(where + " is not a list of 2 or 3 numbers");
    if (dims == 0) dims = static_cast<int>(p.size());
    if (static_cast<int>(p.size()) != dims)
      return corrupt_data(where + " has " + std::to_string(p.size()) + " numbers after points of " +
                          std::to_string(dims));
    cv::Vec3d row(0, 0, 0);
    for (int k = 0; k < dims; ++k) {
      if (!p[k].is_number()) return corrupt_data(where + " is not finite");
      row[k] = p[k].get<double>();
    }
    rows.push_back(row);
    absent.push_back(0);
  }
  if (dims == 0) return corrupt_data(name + ": no points");
  return from_rows(name, rows, dims, allow_null ? absent : std::vector<char>{});
}

Result<LandmarkPoints> read_json_points(const fs::path& path, int dims) {
  const std::string name = path.string();
  GVKIT_ASSIGN_OR_RETURN(const nlohmann::json json, read_json(path));
  if (json.is_array()) return json_list_points(name, json, false);
  if (!json.is_object()) return corrupt_data(name + ": neither a list of points nor an object");
  auto non_empty = [&](const char* key) {
    return json.contains(key) && json[key].is_array() && !json[key].empty();
  };
  // gvkit's own file.
  const bool px = non_empty("points_px"), mm = non_empty("points_mm");
  if (px || mm) {
    const bool use_mm = mm && (dims != 2 || !px);
    return json_list_points(name + (use_mm ? ": points_mm" : ": points_px"),
                            json[use_mm ? "points_mm" : "points_px"], true);
  }
  for (const char* key : {"landmarks", "points"})
    if (json.contains(key)) return json_list_points(name + ": " + key, json[key], false);
  return corrupt_data(name +
                      ": no points (a list, or an object with landmarks, points, points_px or "
                      "points_mm)");
}

}  // namespace

bool is_landmark_file(const fs::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".npy" || ext == ".txt" || ext == ".csv" || ext == ".pts" || ext == ".json";
}

Result<LandmarkPoints> read_landmark_points(const fs::path& path, int dims) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found(path.string() + ": no such file");
  const std::string ext = lower_extension(path);
  if (ext == ".npy") return read_npy_points(path);
  if (ext == ".txt" || ext == ".csv" || ext == ".pts") return read_text_points(path);
  if (ext == ".json") return read_json_points(path, dims);
  return unsupported(path.string() + ": unknown landmark format '" + ext +
                     "' (use .npy, .txt, .csv, .pts or .json)");
}

FaceLandmarks to_face_landmarks(const LandmarkPoints& points, double scale) {
  FaceLandmarks out;
  for (const cv::Vec3d& p : points.points) {
    if (points.dims == 3)
      out.points_mm.emplace_back(cv::Vec3f(p * scale));
    else
      out.points_px.emplace_back(static_cast<float>(p[0]), static_cast<float>(p[1]));
  }
  return out;
}

}  // namespace gvkit
