#include "gvkit/facemap/canonical_domain.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "gvkit/core/json_io.hpp"
#include "gvkit/core/mesh_topology.hpp"
#include "gvkit/facemap/face_boundaries.hpp"

namespace gvkit::facemap {
namespace {

nlohmann::json points_to_json(const std::vector<cv::Point2d>& points) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& p : points) out.push_back({p.x, p.y});
  return out;
}

Result<std::vector<cv::Point2d>> points_from_json(const nlohmann::json& j,
                                                  const std::string& what) {
  if (!j.is_array()) return corrupt_data(what + ": not a list of points");
  std::vector<cv::Point2d> out;
  for (const auto& p : j) {
    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number())
      return corrupt_data(what + ": a point is not [x, y]");
    out.emplace_back(p[0].get<double>(), p[1].get<double>());
  }
  return out;
}

}  // namespace

Result<std::vector<std::vector<double>>> euclidean_distance(
    const Mesh& mesh, const std::vector<Mesh::VertexHandle>& sources, double /*edge_scale*/) {
  std::vector<std::vector<double>> out;
  for (auto s : sources) {
    const Mesh::Point p = mesh.point(s);
    std::vector<double> d(mesh.n_vertices());
    for (auto v : mesh.vertices()) d[v.idx()] = (mesh.point(v) - p).norm();
    out.push_back(std::move(d));
  }
  return out;
}

Result<CanonicalDomainSpec> CanonicalDomainSpec::from_ict(const IctFaceModel& model) {
  const Mesh face = model.face_mesh(model.neutral_mm());
  FaceLandmarks landmarks;
  for (int v : model.landmark_vertices()) {
    const cv::Vec3d& p = model.neutral_mm()[v];
    landmarks.points_mm.emplace_back(p[0], p[1], p[2]);
  }
  GVKIT_ASSIGN_OR_RETURN(FaceBoundaries b, find_face_boundaries(face, landmarks));
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (auto v : face.vertices()) {
    x0 = std::min(x0, face.point(v)[0]), x1 = std::max(x1, face.point(v)[0]);
    y0 = std::min(y0, face.point(v)[1]), y1 = std::max(y1, face.point(v)[1]);
  }
  CanonicalDomainSpec spec;
  spec.width_mm = x1 - x0;
  spec.height_mm = y1 - y0;
  auto normalize = [&](double x, double y) {
    return cv::Point2d((x - x0) / spec.width_mm, (y1 - y) / spec.height_mm);
  };
  auto polygon = [&](const std::vector<Mesh::VertexHandle>& loop) {
    std::vector<cv::Point2d> out;
    for (auto v : loop) out.push_back(normalize(face.point(v)[0], face.point(v)[1]));
    return out;
  };
  spec.eye_right = polygon(b.loops[FaceBoundaries::kEyeRight]);
  spec.eye_left = polygon(b.loops[FaceBoundaries::kEyeLeft]);
  spec.mouth = polygon(b.loops[FaceBoundaries::kMouth]);
  for (const auto& p : landmarks.points_mm) spec.landmarks.push_back(normalize(p[0], p[1]));
  for (int lm : kBoundaryKeyLandmarks) {
    const auto& loop = b.loops[FaceBoundaries::loop_of_landmark(lm)];
    const cv::Vec3f& q = landmarks.points_mm[lm];
    const LoopPoint lp = closest_loop_point(face, loop, Eigen::Vector3d(q[0], q[1], q[2]));
    const auto p = face.point(loop[lp.edge]) * (1.0 - lp.t) +
                   face.point(loop[(lp.edge + 1) % loop.size()]) * lp.t;
    spec.keys[lm] = normalize(p[0], p[1]);
  }
  return spec;
}

Status CanonicalDomainSpec::write(const std::filesystem::path& path) const {
  nlohmann::json j;
  j["format"] = "gvkit canonical face domain";
  j["version"] = kVersion;
  j["source"] =
      "ICT-FaceKit generic_neutral_mesh.obj, face area (vertices 0-9408), frontal projection; "
      "coordinates normalized to the face's bounding box, x right, y down";
  j["width_mm"] = width_mm;
  j["height_mm"] = height_mm;
  j["holes"] = {{"eye_right", points_to_json(eye_right)},
                {"eye_left", points_to_json(eye_left)},
                {"mouth", points_to_json(mouth)}};
  j["landmarks"] = points_to_json(landmarks);
  nlohmann::json keys_json = nlohmann::json::object();
  for (const auto& [lm, p] : keys) keys_json[std::to_string(lm)] = {p.x, p.y};
  j["keys"] = keys_json;
  return write_json(path, j);
}

Result<CanonicalDomainSpec> CanonicalDomainSpec::read(const std::filesystem::path& path) {
  GVKIT_ASSIGN_OR_RETURN(nlohmann::json j, read_json(path));
  const std::string name = path.string();
  if (!j.is_object() || j.value("format", "") != "gvkit canonical face domain")
    return corrupt_data(name + ": not a gvkit canonical face domain");
  if (j.value("version", 0) != kVersion)
    return unsupported(name + ": version " + std::to_string(j.value("version", 0)) +
                       ", this build reads version " + std::to_string(kVersion));
  CanonicalDomainSpec spec;
  if (!j.contains("holes") || !j["holes"].is_object() || !j.contains("landmarks") ||
      !j.contains("keys") || !j["keys"].is_object())
    return corrupt_data(name + ": missing holes, landmarks or keys");
  spec.width_mm = j.value("width_mm", 0.0);
  spec.height_mm = j.value("height_mm", 0.0);
  GVKIT_ASSIGN_OR_RETURN(spec.eye_right,
                         points_from_json(j["holes"]["eye_right"], name + ": eye_right"));
  GVKIT_ASSIGN_OR_RETURN(spec.eye_left,
                         points_from_json(j["holes"]["eye_left"], name + ": eye_left"));
  GVKIT_ASSIGN_OR_RETURN(spec.mouth, points_from_json(j["holes"]["mouth"], name + ": mouth"));
  GVKIT_ASSIGN_OR_RETURN(spec.landmarks, points_from_json(j["landmarks"], name + ": landmarks"));
  if (spec.landmarks.size() != 68) return corrupt_data(name + ": need 68 landmarks");
  for (int lm : kBoundaryKeyLandmarks) {
    const std::string key = std::to_string(lm);
    if (!j["keys"].contains(key)) return corrupt_data(name + ": key " + key + " missing");
    GVKIT_ASSIGN_OR_RETURN(
        auto p, points_from_json(nlohmann::json::array({j["keys"][key]}), name + ": key " + key));
    spec.keys[lm] = p[0];
  }
  for (const auto* poly : {&spec.eye_right, &spec.eye_left, &spec.mouth})
    if (poly->size() < 3) return corrupt_data(name + ": a hole polygon has fewer than 3 points");
  return spec;
}

Result<CanonicalDomainSpec> CanonicalDomainSpec::load_default() {
  if (const char* env = std::getenv("GVKIT_CANONICAL_DOMAIN")) return read(env);
  return read(std::filesystem::path(GVKIT_FACEMAP_DATA_DIR) / "canonical_domain_v1.json");
}

Result<CanonicalDomain> CanonicalDomain::create(const CanonicalDomainSpec& spec, cv::Size size,
                                                RimCorrespondence rim, double min_cotan_weight) {
  const std::string name =
      "canonical domain " + std::to_string(size.width) + "x" + std::to_string(size.height);
  if (size.width < 16 || size.height < 16)
    return invalid_argument(name + ": the domain must be at least 16x16 pixels");
  CanonicalDomain d;
  d.size_ = size;
  // Holes: filled polygons (pixel centres at (x + 0.5) / W), dilated so each is >= 3 px thick.
  auto to_px = [&](const cv::Point2d& p) {
    return cv::Point2d(p.x * size.width - 0.5, p.y * size.height - 0.5);
  };
  cv::Mat holes = cv::Mat::zeros(size, CV_8U);
  for (const auto* poly : {&spec.eye_right, &spec.eye_left, &spec.mouth}) {
    cv::Mat one = cv::Mat::zeros(size, CV_8U);
    std::vector<cv::Point> pts;
    for (const auto& p : *poly) {
      const cv::Point2d q = to_px(p);
      pts.emplace_back(static_cast<int>(std::lround(q.x * 16)),
                       static_cast<int>(std::lround(q.y * 16)));
    }
    cv::fillPoly(one, std::vector<std::vector<cv::Point>>{pts}, cv::Scalar(255), cv::LINE_8, 4);
    cv::dilate(one, one, cv::getStructuringElement(cv::MORPH_CROSS, {3, 3}));
    cv::Mat overlap;
    cv::bitwise_and(one, holes, overlap);
    if (cv::countNonZero(overlap) > 0) return failed_precondition(name + ": holes overlap");
    holes |= one;
  }
  // A hole touching the border or another hole (within one pixel) would break the annulus.
  cv::Mat grown;
  cv::dilate(holes, grown, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  for (int x = 0; x < size.width; ++x)
    if (grown.at<uint8_t>(0, x) || grown.at<uint8_t>(size.height - 1, x))
      return failed_precondition(name + ": a hole touches the border");
  for (int y = 0; y < size.height; ++y)
    if (grown.at<uint8_t>(y, 0) || grown.at<uint8_t>(y, size.width - 1))
      return failed_precondition(name + ": a hole touches the border");

  // One vertex per domain pixel at (x, -y, 0) (so the triangles are counter-clockwise seen from
  // the front, like the face), two triangles per 2x2 block of domain pixels.
  Mesh mesh;
  std::vector<Mesh::VertexHandle> vertex(size.area());
  auto inside = [&](int x, int y) { return holes.at<uint8_t>(y, x) == 0; };
  std::vector<char> used(size.area(), 0);
  for (int y = 0; y + 1 < size.height; ++y)
    for (int x = 0; x + 1 < size.width; ++x)
      if (inside(x, y) && inside(x + 1, y) && inside(x, y + 1) && inside(x + 1, y + 1))
        used[y * size.width + x] = used[y * size.width + x + 1] = used[(y + 1) * size.width + x] =
            used[(y + 1) * size.width + x + 1] = 1;
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      if (used[y * size.width + x])
        vertex[y * size.width + x] = mesh.add_vertex(Mesh::Point(x, -y, 0));
  for (int y = 0; y + 1 < size.height; ++y)
    for (int x = 0; x + 1 < size.width; ++x)
      if (inside(x, y) && inside(x + 1, y) && inside(x, y + 1) && inside(x + 1, y + 1)) {
        const auto a = vertex[y * size.width + x], b = vertex[y * size.width + x + 1];
        const auto c = vertex[(y + 1) * size.width + x + 1], e = vertex[(y + 1) * size.width + x];
        mesh.add_face(a, e, c);
        mesh.add_face(a, c, b);
      }
  const MeshTopology topo = mesh_topology(mesh);
  if (topo.components != 1 || topo.boundary_loops != 4 || topo.genus != 0)
    return failed_precondition(name +
                               ": the rasterized domain is not a rectangle with 3 "
                               "separate holes (too small a size?)");
  // Map pixel index -> mesh vertex index (vertices were added in pixel order).
  std::vector<int> pixel_of_vertex;
  for (int i = 0; i < size.area(); ++i)
    if (used[i]) pixel_of_vertex.push_back(i);

  FaceLandmarks landmarks;
  for (int i = 0; i < 68; ++i) {
    cv::Point2d p = to_px(spec.landmarks[i]);
    auto it = spec.keys.find(i);
    if (it != spec.keys.end()) p = to_px(it->second);
    landmarks.points_mm.emplace_back(static_cast<float>(p.x), static_cast<float>(-p.y), 0.f);
  }
  FaceAnnulusOptions options;
  options.boundaries.landmark_tolerance_mm = 1e9;  // pixels here; the holes are where the spec says
  options.boundaries.min_triangle_area_mm2 = 0;
  options.key_snap_fraction = 0.5;  // keys land on pixel centres
  options.slide_along_start = true;
  options.distance_crop_mm = 0;  // Euclidean distances cost nothing to solve
  GVKIT_ASSIGN_OR_RETURN(d.annulus_,
                         make_face_annulus(mesh, landmarks, euclidean_distance, options));
  GVKIT_ASSIGN_OR_RETURN(
      d.flow_, flow_coordinates(d.annulus_, {}, rim, min_cotan_weight, HarmonicSolver::kAuto));

  const TriSurface& s = d.annulus_.surface;
  d.st_.assign(size.area(), Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN()));
  d.mask_ = cv::Mat::zeros(size, CV_8U);
  for (int k = 0; k < s.n_triangles(); ++k)
    for (int j = 0; j < 3; ++j) {
      const int v = s.triangles[k][j];
      if (s.source[v].size() != 1) continue;  // a vertex inserted by a cut, not a pixel
      const int pixel = pixel_of_vertex[s.source[v][0].vertex];
      if (!std::isnan(d.st_[pixel].x())) continue;
      double sv = d.flow_.corner_s[3 * k + j];
      sv -= std::floor(sv);
      d.st_[pixel] = {sv, d.flow_.t[v]};
      d.mask_.at<uint8_t>(pixel / size.width, pixel % size.width) = 255;
    }
  std::vector<Eigen::Vector2d> st_corners(3 * s.n_triangles());
  d.corner_pixels_.resize(3 * s.n_triangles());
  for (int k = 0; k < s.n_triangles(); ++k)
    for (int j = 0; j < 3; ++j) {
      const int v = s.triangles[k][j];
      st_corners[3 * k + j] = {d.flow_.corner_s[3 * k + j], d.flow_.t[v]};
      d.corner_pixels_[3 * k + j] = {s.xyz[v].x(), -s.xyz[v].y()};
    }
  d.st_locator_ = std::make_shared<TriangleLocator>(std::move(st_corners));
  for (const auto& key : d.annulus_.keys) {
    const int v = d.annulus_.inner_loop[key.position];
    d.key_pixels_[key.name] = {s.xyz[v].x(), -s.xyz[v].y()};
  }
  return d;
}

Eigen::Vector2d CanonicalDomain::pixel_of(double s, double t) const {
  const double base = s - std::floor(s);
  TriangleLocator::Hit best;
  double best_min = -INFINITY;
  for (double shift : {0.0, 1.0, -1.0}) {
    const auto hit = st_locator_->locate({base + shift, t}, 1e-6);
    if (hit.triangle < 0) continue;
    const double mn = std::min({hit.barycentric[0], hit.barycentric[1], hit.barycentric[2]});
    if (mn > best_min) best_min = mn, best = hit;
    if (mn >= 0) break;
  }
  if (best.triangle < 0) return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  for (int j = 0; j < 3; ++j) p += best.barycentric[j] * corner_pixels_[3 * best.triangle + j];
  return p;
}

}  // namespace gvkit::facemap
