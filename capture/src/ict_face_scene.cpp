#include "gvkit/capture/ict_face_scene.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "rasterizer.hpp"

namespace gvkit::capture {
namespace {

const std::vector<std::string> kExpressions = {
    "jawOpen",    "mouthSmile_L",  "mouthSmile_R",  "mouthFunnel", "mouthPucker", "eyeBlink_L",
    "eyeBlink_R", "browInnerUp_L", "browInnerUp_R", "cheekPuff_L", "cheekPuff_R"};

bool rendered(IctRegion r) { return r != IctRegion::kEyeExtras && r != IctRegion::kEyelashes; }

// Distance from point p to the segment a-b (2D).
double segment_distance(cv::Point2d p, cv::Point2d a, cv::Point2d b) {
  const cv::Point2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.dot(ab), 1e-12), 0.0, 1.0);
  return cv::norm(p - (a + t * ab));
}

double polyline_distance(cv::Point2d p, const std::vector<cv::Point2d>& line, bool closed) {
  double d = INFINITY;
  for (size_t i = 0; i + 1 < line.size(); ++i)
    d = std::min(d, segment_distance(p, line[i], line[i + 1]));
  if (closed) d = std::min(d, segment_distance(p, line.back(), line.front()));
  return d;
}

// Per-vertex albedo from regions and the neutral face's landmarks (frontal projection).
std::vector<float> make_albedo(const IctFaceModel& model) {
  const auto& p = model.neutral_mm();
  const auto& lm = model.landmark_vertices();
  auto landmark = [&](int i) { return cv::Point2d(p[lm[i]][0], p[lm[i]][1]); };
  auto polyline = [&](int first, int last) {
    std::vector<cv::Point2d> line;
    for (int i = first; i <= last; ++i) line.push_back(landmark(i));
    return line;
  };
  const auto brow_r = polyline(17, 21), brow_l = polyline(22, 26);
  const auto lips = polyline(48, 59), eye_r = polyline(36, 41), eye_l = polyline(42, 47);
  std::vector<cv::Point2f> lips_f(lips.begin(), lips.end());
  // The sclera and iris meshes are both whole eyeball shells: paint iris and pupil onto the
  // front of both, around the eyeball's axis (the eyes look forward in the neutral pose).
  // Sclera 21451-22220 + iris 22221-23020 are one eye, 23021-24590 the other.
  auto eye_of = [](int v) { return v < 23021 ? 0 : 1; };
  cv::Point2d eye_centre[2] = {{0, 0}, {0, 0}};
  double eye_front_z[2] = {-INFINITY, -INFINITY};
  int eye_count[2] = {0, 0};
  for (int v = 21451; v < 24591; ++v) {
    const int e = eye_of(v);
    eye_centre[e] += cv::Point2d(p[v][0], p[v][1]);
    eye_front_z[e] = std::max(eye_front_z[e], p[v][2]);
    ++eye_count[e];
  }
  for (int e = 0; e < 2; ++e) eye_centre[e] *= 1.0 / std::max(1, eye_count[e]);
  auto eye_albedo = [&](int v) {
    const int e = eye_of(v);
    const double r = cv::norm(cv::Point2d(p[v][0], p[v][1]) - eye_centre[e]);
    if (p[v][2] < eye_front_z[e] - 6.0) return 0.88f;
    if (r < 2.0) return 0.04f;
    if (r < 5.8) return 0.22f;
    return 0.88f;
  };

  std::vector<float> albedo(p.size(), 0.7f);
  for (int v = 0; v < static_cast<int>(p.size()); ++v) {
    const cv::Point2d q(p[v][0], p[v][1]);
    switch (IctFaceModel::region_of(v)) {
      case IctRegion::kFace: {
        float a = 0.74f;
        const double brow =
            std::min(polyline_distance(q, brow_r, false), polyline_distance(q, brow_l, false));
        if (brow < 4.5) a = 0.30f;
        if (cv::pointPolygonTest(lips_f, cv::Point2f(q), true) > -1.0) a = 0.40f;
        const double lid =
            std::min(polyline_distance(q, eye_r, true), polyline_distance(q, eye_l, true));
        if (lid < 1.8) a = 0.28f;
        albedo[v] = a;
        break;
      }
      case IctRegion::kHeadAndNeck:
        albedo[v] = 0.70f;
        break;
      case IctRegion::kMouthSocket:
        albedo[v] = 0.12f;
        break;
      case IctRegion::kEyeSocket:
        albedo[v] = 0.2f;
        break;
      case IctRegion::kGumsAndTongue:
        albedo[v] = 0.35f;
        break;
      case IctRegion::kTeeth:
        albedo[v] = 0.8f;
        break;
      case IctRegion::kSclera:
      case IctRegion::kIris:
        albedo[v] = eye_albedo(v);
        break;
      default:
        albedo[v] = 0.5f;
    }
  }
  return albedo;
}

}  // namespace

Status IctFaceSceneOptions::check() const {
  if (!(distance_mm > 100 && distance_mm < 10000))
    return invalid_argument("face distance must be in (100, 10000) mm");
  return Status::ok();
}

Result<IctFaceScene> IctFaceScene::load(const std::filesystem::path& ict_dir,
                                        const IctFaceSceneOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  GVKIT_ASSIGN_OR_RETURN(IctFaceModel model, IctFaceModel::load(ict_dir, kExpressions));
  IctFaceScene s;
  s.model_ = std::move(model);
  s.options_ = options;
  s.albedo_ = make_albedo(s.model_);
  const auto& polygons = s.model_.polygons();
  for (size_t i = 0; i < polygons.size(); ++i) {
    const auto& poly = polygons[i];
    bool keep = true;
    for (const auto& c : poly) keep = keep && rendered(IctFaceModel::region_of(c.vertex));
    if (!keep) continue;
    for (size_t k = 1; k + 1 < poly.size(); ++k) {
      s.triangles_.emplace_back(poly[0].vertex, poly[k].vertex, poly[k + 1].vertex);
      s.triangle_polygon_.push_back(static_cast<int>(i));
    }
  }
  cv::Vec3d centre(0, 0, 0);
  for (int v : s.model_.landmark_vertices()) centre += s.model_.neutral_mm()[v];
  s.centre_mm_ = centre / 68.0;
  return s;
}

std::vector<cv::Vec3d> IctFaceScene::positions_mm(const ExpressionPose& pose) const {
  std::vector<cv::Vec3d> p = model_.evaluate(pose.weights);
  const double d2r = CV_PI / 180.0;
  const cv::Vec3d r = pose.head_rotation_deg * d2r;
  cv::Matx33d yaw, pitch, roll;
  cv::Rodrigues(cv::Vec3d(0, r[0], 0), yaw);
  cv::Rodrigues(cv::Vec3d(r[1], 0, 0), pitch);
  cv::Rodrigues(cv::Vec3d(0, 0, r[2]), roll);
  // Model frame (y up, z towards the viewer) -> camera frame (y down, z forward).
  const cv::Matx33d flip(1, 0, 0, 0, -1, 0, 0, 0, -1);
  const cv::Matx33d R = yaw * pitch * roll * flip;
  const cv::Vec3d t = cv::Vec3d(0, 0, options_.distance_mm) + pose.head_translation_mm;
  for (auto& v : p) v = R * (v - centre_mm_) + t;
  return p;
}

SyntheticScene IctFaceScene::scene(const ExpressionPose& pose) const {
  SyntheticScene s;
  s.positions_mm = positions_mm(pose);
  s.triangles = triangles_;
  s.triangle_source = triangle_polygon_;
  s.albedo = albedo_;
  return s;
}

FaceLandmarks IctFaceScene::landmarks(const ExpressionPose& pose,
                                      const Calibration& calibration) const {
  const std::vector<cv::Vec3d> p = positions_mm(pose);
  FaceLandmarks lm;
  for (int v : model_.landmark_vertices()) {
    lm.points_mm.push_back(cv::Vec3f(p[v]));
    const cv::Point2d px =
        detail::project_point(p[v], calibration.camera_K, calibration.camera_dist);
    lm.points_px.emplace_back(static_cast<float>(px.x), static_cast<float>(px.y));
  }
  return lm;
}

}  // namespace gvkit::capture
