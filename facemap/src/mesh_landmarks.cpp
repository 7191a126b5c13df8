#include "gvkit/facemap/mesh_landmarks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "triangle_raster.hpp"

namespace gvkit::facemap {

namespace {

cv::Vec3d point_of(const Mesh& mesh, Mesh::VertexHandle v) {
  const auto& p = mesh.point(v);
  return {p[0], p[1], p[2]};
}

// Vertex grey values from the colours when they vary over the mesh (a textured scan); empty when
// the mesh has none or one colour everywhere (e.g. a constant grey written for an untextured mesh).
std::vector<double> vertex_grey(const Mesh& mesh) {
  if (!mesh.has_vertex_colors() || mesh.n_vertices() == 0) return {};
  std::vector<double> grey;
  grey.reserve(mesh.n_vertices());
  double lo = 1e9, hi = -1e9;
  for (auto v : mesh.vertices()) {
    const auto& c = mesh.color(v);
    const double g = 0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2];
    grey.push_back(g);
    lo = std::min(lo, g);
    hi = std::max(hi, g);
  }
  if (hi - lo < 1e-3) return {};
  return grey;
}

// Rotates `v` about the unit axis `k` by `deg` degrees (Rodrigues).
cv::Vec3d rotated(const cv::Vec3d& v, const cv::Vec3d& k, double deg) {
  const double a = deg * CV_PI / 180.0;
  return v * std::cos(a) + k.cross(v) * std::sin(a) + k * k.dot(v) * (1 - std::cos(a));
}

}  // namespace

Status MeshRenderOptions::check() const {
  if (size_px < 64 || size_px > 4096)
    return invalid_argument("mesh render: size must be in 64..4096 px, got " +
                            std::to_string(size_px));
  if (!(fill > 0.1 && fill <= 1.0))
    return invalid_argument("mesh render: fill must be in (0.1, 1], got " + std::to_string(fill));
  if (cv::norm(light) < 1e-9) return invalid_argument("mesh render: light direction is zero");
  if (!(pixel_mm >= 0 && std::isfinite(pixel_mm)))
    return invalid_argument("mesh render: pixel size must be >= 0");
  return Status::ok();
}

Status MeshLandmarkOptions::check() const {
  GVKIT_RETURN_IF_ERROR(render.check());
  if (!(max_gap_px >= 0.0 && max_gap_px <= 100.0))
    return invalid_argument("mesh landmarks: max gap must be in 0..100 px");
  if (!(max_cavity_depth >= 0.0 && max_cavity_depth <= 1.0))
    return invalid_argument("mesh landmarks: max cavity depth must be in [0, 1]");
  if (!(face_fill > 0.1 && face_fill <= 1.0))
    return invalid_argument("mesh landmarks: face fill must be in (0.1, 1]");
  if (!(min_face_span >= 0.0 && min_face_span <= 1.0))
    return invalid_argument("mesh landmarks: min face span must be in [0, 1]");
  if (!(max_oblique_deg >= 0.0 && max_oblique_deg <= 180.0))
    return invalid_argument("mesh landmarks: max oblique angle must be in [0, 180] degrees");
  if (!(std::abs(frontal_pitch_deg) <= 45.0))
    return invalid_argument("mesh landmarks: frontal pitch must be in [-45, 45] degrees");
  return Status::ok();
}

cv::Vec2d MeshRender::pixel_of(const cv::Vec3d& p_mesh_mm) const {
  const cv::Vec3d c = cam_from_mesh * (p_mesh_mm - centre_mm);
  const double half = (image.cols - 1) / 2.0;
  return {c[0] / pixel_mm + half, -c[1] / pixel_mm + half};
}

Result<cv::Vec3d> frontal_view_direction(const Mesh& mesh) {
  if (mesh.n_vertices() == 0 || mesh.n_faces() == 0)
    return invalid_argument("mesh has no triangles to find a frontal view of");
  cv::Vec3d normal_sum(0, 0, 0), centroid(0, 0, 0);
  for (auto f : mesh.faces()) {
    auto fv = mesh.cfv_iter(f);
    const cv::Vec3d a = point_of(mesh, *fv), b = point_of(mesh, *++fv), c = point_of(mesh, *++fv);
    normal_sum += 0.5 * (b - a).cross(c - a);
  }
  for (auto v : mesh.vertices()) centroid += point_of(mesh, v);
  centroid /= static_cast<double>(mesh.n_vertices());
  const double length = cv::norm(normal_sum);
  if (length < 1e-12) return invalid_argument("mesh normals cancel out: no frontal direction");
  cv::Vec3d view = normal_sum / length;

  // The longest boundary loop (the face's rim): the surface bulges towards the viewer from it.
  std::vector<char> seen(mesh.n_halfedges(), 0);
  double best_length = 0.0;
  cv::Vec3d rim_centroid(0, 0, 0);
  for (auto h : mesh.halfedges()) {
    if (!mesh.is_boundary(h) || seen[h.idx()]) continue;
    double loop_length = 0.0;
    cv::Vec3d sum(0, 0, 0);
    int count = 0;
    for (auto g = h; !seen[g.idx()]; g = mesh.next_halfedge_handle(g)) {
      seen[g.idx()] = 1;
      const cv::Vec3d p = point_of(mesh, mesh.from_vertex_handle(g));
      loop_length += cv::norm(point_of(mesh, mesh.to_vertex_handle(g)) - p);
      sum += p;
      ++count;
    }
    if (loop_length > best_length) {
      best_length = loop_length;
      rim_centroid = sum / count;
    }
  }
  if (best_length > 0.0 && (centroid - rim_centroid).dot(view) < 0) view = -view;
  return view;
}

MeshRender render_mesh(const Mesh& mesh, const cv::Vec3d& view_direction, const cv::Vec3d& up,
                       const MeshRenderOptions& options, const MeshTexture* texture) {
  GVKIT_CHECK(options.check().is_ok(), "render_mesh: bad options");
  if (texture && texture->empty()) texture = nullptr;
  GVKIT_CHECK(!texture || texture->face_image.size() == mesh.n_faces(),
              "render_mesh: one texture entry per face");
  const cv::Vec3d z = view_direction / cv::norm(view_direction);
  cv::Vec3d y = up - z * z.dot(up);
  GVKIT_CHECK(cv::norm(y) > 1e-9, "render_mesh: up is parallel to the view direction");
  y /= cv::norm(y);
  const cv::Vec3d x = y.cross(z);
  MeshRender r;
  r.cam_from_mesh = cv::Matx33d(x[0], x[1], x[2], y[0], y[1], y[2], z[0], z[1], z[2]);
  const int n = options.size_px;

  // Fit the projected bounding box into the image.
  std::vector<cv::Vec3d> cam(mesh.n_vertices());
  cv::Vec2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (auto v : mesh.vertices()) {
    const cv::Vec3d c = r.cam_from_mesh * point_of(mesh, v);
    cam[v.idx()] = c;
    lo = {std::min(lo[0], c[0]), std::min(lo[1], c[1])};
    hi = {std::max(hi[0], c[0]), std::max(hi[1], c[1])};
  }
  cv::Vec3d centre_cam((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, 0.0);
  r.pixel_mm = std::max({hi[0] - lo[0], hi[1] - lo[1], 1e-9}) / (options.fill * (n - 1));
  if (options.pixel_mm > 0) {  // framed by the caller
    const cv::Vec3d c = r.cam_from_mesh * options.centre_mm;
    centre_cam = {c[0], c[1], 0.0};
    r.pixel_mm = options.pixel_mm;
  }
  r.centre_mm = r.cam_from_mesh.t() * centre_cam;
  for (auto& c : cam) c = c - centre_cam;

  const std::vector<double> grey = vertex_grey(mesh);
  r.coloured = !grey.empty() || texture;
  r.textured = texture != nullptr;
  r.image = cv::Mat(n, n, CV_32F, cv::Scalar(0.0f));
  r.triangle = cv::Mat(n, n, CV_32S, cv::Scalar(-1));
  r.depth = cv::Mat(n, n, CV_64F, cv::Scalar(-std::numeric_limits<double>::infinity()));
  cv::Mat& depth = r.depth;
  const cv::Vec3d light = options.light / cv::norm(options.light);
  const double half = (n - 1) / 2.0;
  for (auto f : mesh.faces()) {
    int vi[3];
    auto fv = mesh.cfv_iter(f);
    for (int j = 0; j < 3; ++j, ++fv) vi[j] = fv->idx();
    cv::Vec2d px[3];
    for (int j = 0; j < 3; ++j)
      px[j] = {cam[vi[j]][0] / r.pixel_mm + half, -cam[vi[j]][1] / r.pixel_mm + half};
    cv::Vec3d normal = (cam[vi[1]] - cam[vi[0]]).cross(cam[vi[2]] - cam[vi[0]]);
    normal /= std::max(cv::norm(normal), 1e-12);
    // Two-sided Lambert: the winding of a given mesh is not known to face the viewer.
    const double shade = 0.15 + 0.85 * std::abs(normal.dot(light));
    const int image = texture ? texture->face_image[f.idx()] : -1;
    rasterize_triangle(px, n, n, [&](int xx, int yy, const double(&w)[3]) {
      const double d = w[0] * cam[vi[0]][2] + w[1] * cam[vi[1]][2] + w[2] * cam[vi[2]][2];
      if (d <= depth.at<double>(yy, xx)) return;  // z points to the viewer: larger is nearer
      depth.at<double>(yy, xx) = d;
      r.triangle.at<int>(yy, xx) = f.idx();
      double value = 0.8 * shade;
      if (image >= 0) {
        const auto& uv = texture->face_uv[f.idx()];
        value =
            sample_texture_grey(texture->images[image], w[0] * uv[0] + w[1] * uv[1] + w[2] * uv[2]);
      } else if (!grey.empty()) {
        value = (w[0] * grey[vi[0]] + w[1] * grey[vi[1]] + w[2] * grey[vi[2]]) * shade;
      }
      r.image.at<float>(yy, xx) = static_cast<float>(std::clamp(value, 0.0, 1.0));
    });
  }
  return r;
}

namespace {

// Lifts every point of out.landmarks.points_px (in out.render) onto the surface through the
// triangle under it (or the nearest covered pixel).
Status lift_landmarks(const Mesh& mesh, const std::string& name, const MeshLandmarkOptions& options,
                      MeshLandmarks* result) {
  MeshLandmarks& out = *result;
  const MeshRender& r = out.render;
  const int n = r.image.cols;
  const double half = (n - 1) / 2.0;
  out.landmarks.points_mm.clear();
  out.gap_filled = out.cavity_moved = 0;
  // The face's width in the render (mm), for the depth of a cavity.
  float lo = 1e30f, hi = -1e30f;
  for (const auto& p : out.landmarks.points_px) lo = std::min(lo, p.x), hi = std::max(hi, p.x);
  const double face_mm = std::max(0.0f, hi - lo) * r.pixel_mm;
  for (int i = 0; i < FaceLandmarks::kCount; ++i) {
    cv::Point2f p = out.landmarks.points_px[i];
    int px = std::clamp(static_cast<int>(std::lround(p.x)), 0, n - 1);
    int py = std::clamp(static_cast<int>(std::lround(p.y)), 0, n - 1);
    int tri = r.triangle.at<int>(py, px);
    // An eye or lip contour point seen through an opening into a cavity (an eye socket, the
    // mouth of a whole head) lands deep behind the lids or lips: the surface under it is cut off
    // from the front surface around it by a depth jump (an occluding edge, not a slope like a
    // mouth corner's), and it moves to the nearest pixel of that front surface.
    if (tri >= 0 && i >= 36 && options.max_cavity_depth > 0) {
      const int reach = static_cast<int>(std::ceil(options.max_gap_px));
      const int y0 = std::max(0, py - reach), y1 = std::min(n - 1, py + reach);
      const int x0 = std::max(0, px - reach), x1 = std::min(n - 1, px + reach);
      const int w = x1 - x0 + 1;
      auto depth = [&](int x, int y) { return r.depth.at<double>(y, x); };
      double front = -std::numeric_limits<double>::infinity();
      for (int yy = y0; yy <= y1; ++yy)
        for (int xx = x0; xx <= x1; ++xx) front = std::max(front, depth(xx, yy));
      const double step = options.max_cavity_depth * face_mm;
      // The pixels reached from the point without crossing a jump: the point's own layer.
      const double jump = std::max(5.0 * r.pixel_mm, 0.25 * step);
      std::vector<char> layer(static_cast<size_t>(w) * (y1 - y0 + 1), 0);
      std::vector<std::pair<int, int>> stack = {{px, py}};
      layer[(py - y0) * w + (px - x0)] = 1;
      double layer_front = depth(px, py);
      while (!stack.empty()) {
        const auto [x, y] = stack.back();
        stack.pop_back();
        layer_front = std::max(layer_front, depth(x, y));
        const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
        for (int k = 0; k < 4; ++k) {
          const int xx = x + dx[k], yy = y + dy[k];
          if (xx < x0 || xx > x1 || yy < y0 || yy > y1 || layer[(yy - y0) * w + (xx - x0)] ||
              r.triangle.at<int>(yy, xx) < 0 || std::abs(depth(xx, yy) - depth(x, y)) > jump)
            continue;
          layer[(yy - y0) * w + (xx - x0)] = 1;
          stack.emplace_back(xx, yy);
        }
      }
      if (layer_front < front - step) {
        double best = 1e300;
        for (int yy = y0; yy <= y1; ++yy)
          for (int xx = x0; xx <= x1; ++xx) {
            const double d2 = (xx - p.x) * (xx - p.x) + (yy - p.y) * (yy - p.y);
            if (!layer[(yy - y0) * w + (xx - x0)] && depth(xx, yy) >= front - step && d2 < best)
              best = d2, px = xx, py = yy;
          }
        p = cv::Point2f(static_cast<float>(px), static_cast<float>(py));
        out.landmarks.points_px[i] = p;
        tri = r.triangle.at<int>(py, px);
        ++out.cavity_moved;
      }
    }
    if (tri < 0) {
      const int reach = static_cast<int>(std::ceil(options.max_gap_px));
      double best = 1e300;
      for (int yy = std::max(0, py - reach); yy <= std::min(n - 1, py + reach); ++yy)
        for (int xx = std::max(0, px - reach); xx <= std::min(n - 1, px + reach); ++xx) {
          const int t = r.triangle.at<int>(yy, xx);
          const double d2 = (xx - p.x) * (xx - p.x) + (yy - p.y) * (yy - p.y);
          if (t >= 0 && d2 < best && d2 <= options.max_gap_px * options.max_gap_px) {
            best = d2;
            tri = t;
          }
        }
      if (tri < 0)
        return failed_precondition(name + ": landmark " + std::to_string(i) +
                                   " lies on no rendered surface within " +
                                   std::to_string(options.max_gap_px) + " px");
      ++out.gap_filled;
    }
    // Barycentric position of the sub-pixel point in the triangle's projection, clamped into it.
    cv::Vec3d corner[3];
    cv::Vec2d cp[3];
    auto fv = mesh.cfv_iter(Mesh::FaceHandle(tri));
    for (int j = 0; j < 3; ++j, ++fv) {
      corner[j] = point_of(mesh, *fv);
      const cv::Vec3d c = r.cam_from_mesh * (corner[j] - r.centre_mm);
      cp[j] = {c[0] / r.pixel_mm + half, -c[1] / r.pixel_mm + half};
    }
    const double area = (cp[1][0] - cp[0][0]) * (cp[2][1] - cp[0][1]) -
                        (cp[2][0] - cp[0][0]) * (cp[1][1] - cp[0][1]);
    double w[3], sum = 0.0;
    for (int j = 0; j < 3; ++j) {
      const cv::Vec2d& a = cp[(j + 1) % 3];
      const cv::Vec2d& b = cp[(j + 2) % 3];
      w[j] = std::max(0.0, ((b[0] - a[0]) * (p.y - a[1]) - (b[1] - a[1]) * (p.x - a[0])) / area);
      sum += w[j];
    }
    if (sum < 1e-12) w[0] = w[1] = w[2] = sum = 1.0;
    const cv::Vec3d q = (w[0] * corner[0] + w[1] * corner[1] + w[2] * corner[2]) / sum;
    out.landmarks.points_mm.emplace_back(q);
  }
  return Status::ok();
}

}  // namespace

Result<MeshLandmarks> detect_mesh_landmarks(const Mesh& mesh, const LandmarkDetector& detector,
                                            const std::string& name,
                                            const MeshLandmarkOptions& options,
                                            const MeshTexture* texture) {
  GVKIT_RETURN_IF_ERROR(options.check());
  if (mesh.n_faces() == 0) return failed_precondition(name + ": the mesh has no faces");
  // Views: the mean normal (when there is one), then the model's axes not near a view tried.
  std::vector<std::pair<cv::Vec3d, std::string>> views;
  if (auto view = frontal_view_direction(mesh); view.is_ok())
    views.emplace_back(*view, "mean normal");
  const std::pair<cv::Vec3d, const char*> axes[] = {{{0, 0, 1}, "+z"}, {{0, 0, -1}, "-z"},
                                                    {{0, 1, 0}, "+y"}, {{0, -1, 0}, "-y"},
                                                    {{1, 0, 0}, "+x"}, {{-1, 0, 0}, "-x"}};
  for (const auto& [axis, axis_name] : axes) {
    bool near = false;
    for (const auto& v : views) near |= axis.dot(v.first) > std::cos(30.0 * CV_PI / 180.0);
    if (!near) views.emplace_back(axis, axis_name);
  }
  MeshLandmarks out;
  bool found = false;
  for (const auto& [view, view_name] : views) {
    // Model +y up, unless the view looks along it.
    cv::Vec3d up0(0, 1, 0);
    if (std::abs(up0.dot(view)) > 0.9) up0 = {0, 0, 1};
    for (int roll : {0, 180, 90, 270}) {
      ++out.views_tried;
      MeshRender render =
          render_mesh(mesh, view, rotated(up0, view, roll), options.render, texture);
      auto detected = detector.detect(render.image);
      if (!detected.is_ok()) continue;
      out.landmarks = std::move(detected).value();
      out.render = std::move(render);
      out.view = view;
      out.view_name = view_name;
      out.roll_deg = roll;
      found = true;
      break;
    }
    if (found) break;
  }
  const bool textured = texture && !texture->empty();
  if (!found)
    return failed_precondition(
        name + ": dlib found no face in renders of the mesh (" +
        std::string(textured ? "its texture"
                             : (mesh.has_vertex_colors() ? "vertex colours or shading"
                                                         : "shaded, no colours")) +
        ", " + std::to_string(views.size()) + " views x 4 rolls); give its landmarks in a file");
  GVKIT_RETURN_IF_ERROR(lift_landmarks(mesh, name, options, &out));

  // The view found may show the face small (a whole head) or obliquely: then look again straight
  // at the face the landmarks span (eyes and mouth upright), framed on it, and keep what is found
  // there.
  const auto& q = out.landmarks.points_mm;
  cv::Vec3d right(0, 0, 0), left(0, 0, 0), mouth(0, 0, 0);
  for (int i = 36; i < 42; ++i) right += cv::Vec3d(q[i]) / 6.0;
  for (int i = 42; i < 48; ++i) left += cv::Vec3d(q[i]) / 6.0;
  for (int i = 48; i < 68; ++i) mouth += cv::Vec3d(q[i]) / 20.0;
  const cv::Vec3d eye_axis = (left - right) / std::max(cv::norm(left - right), 1e-12);
  // The normal of the eyes-mouth plane looks down on a face (the mouth stands out in front of the
  // eyes); a frontal camera is level: turned down about the eye axis by frontal_pitch_deg.
  const cv::Vec3d eyes_to_mouth_up = 0.5 * (right + left) - mouth;
  const cv::Vec3d up = rotated(eyes_to_mouth_up, eye_axis, options.frontal_pitch_deg);
  const cv::Vec3d facing =
      rotated((left - right).cross(eyes_to_mouth_up), eye_axis, options.frontal_pitch_deg);
  cv::Point2f lo(1e30f, 1e30f), hi(-1e30f, -1e30f);
  for (int i = 17; i < FaceLandmarks::kCount; ++i) {
    const cv::Point2f& p = out.landmarks.points_px[i];
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  }
  const double span = std::max(hi.x - lo.x, hi.y - lo.y) / out.render.image.cols;
  const double oblique_deg =
      cv::norm(facing) > 1e-12
          ? std::acos(std::clamp(out.view.dot(facing / cv::norm(facing)), -1.0, 1.0)) * 180 / CV_PI
          : 0.0;
  const bool small = span < options.min_face_span;
  if ((small || oblique_deg > options.max_oblique_deg) && cv::norm(facing) > 1e-12 &&
      cv::norm(up) > 1e-12) {
    MeshRenderOptions framed = options.render;
    cv::Vec3d centre(0, 0, 0);
    double extent = 0;
    for (int i = 17; i < 68; ++i) centre += cv::Vec3d(q[i]) / 51.0;
    for (int i = 17; i < 68; ++i) extent = std::max(extent, cv::norm(cv::Vec3d(q[i]) - centre));
    framed.centre_mm = centre;
    framed.pixel_mm = 2.0 * extent / (options.face_fill * (framed.size_px - 1));
    MeshLandmarks again;
    again.render = render_mesh(mesh, facing / cv::norm(facing), up, framed, texture);
    auto detected = detector.detect(again.render.image);
    if (detected.is_ok()) {
      again.landmarks = std::move(detected).value();
      if (lift_landmarks(mesh, name, options, &again).is_ok()) {
        again.view = facing / cv::norm(facing);
        again.view_name = out.view_name + ", then straight at the face";
        again.views_tried = out.views_tried + 1;
        again.roll_deg = out.roll_deg;
        return again;
      }
    }
  }
  return out;
}

Result<FaceLandmarks> landmarks_on_mesh(const LandmarkPoints& points, const Mesh& mesh,
                                        const MeshTexture& texture, double scale,
                                        const std::string& file) {
  GVKIT_CHECK(points.points.size() == FaceLandmarks::kCount, "68 landmark points");
  if (points.dims == 3) return to_face_landmarks(points, scale);
  // 2-D: pixels of the texture image.
  if (texture.empty())
    return failed_precondition(file +
                               ": 2-D points on a mesh must be pixels of its texture image, and "
                               "the mesh has none; give 3-D points (in the mesh file's units)");
  if (texture.images.size() != 1)
    return failed_precondition(file + ": 2-D points, but the mesh has " +
                               std::to_string(texture.images.size()) +
                               " texture images: which one they are on is ambiguous; give 3-D "
                               "points");
  std::vector<cv::Point2f> pixels;
  for (const auto& p : points.points)
    pixels.emplace_back(static_cast<float>(p[0]), static_cast<float>(p[1]));
  GVKIT_ASSIGN_OR_RETURN(std::vector<cv::Vec3d> xyz,
                         surface_points_of_texture_pixels(mesh, texture, 0, pixels, file));
  FaceLandmarks out;
  out.points_px = pixels;  // in the texture image
  for (const auto& p : xyz) out.points_mm.emplace_back(cv::Vec3f(p));
  return out;
}

}  // namespace gvkit::facemap
