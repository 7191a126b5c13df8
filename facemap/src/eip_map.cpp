#include "gvkit/facemap/eip_map.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "gvkit/facemap/map_metrics.hpp"
#include "gvkit/facemap/nearest_vertices.hpp"
#include "gvkit/facemap/triangle_locator.hpp"
#include "thread_cpu_time.hpp"

namespace gvkit::facemap {

DistanceFunction heat_geodesic_distance(const HeatGeodesicsOptions& options) {
  return [options](const Mesh& mesh, const std::vector<Mesh::VertexHandle>& sources,
                   double edge_scale) -> Result<std::vector<std::vector<double>>> {
    GVKIT_RETURN_IF_ERROR(options.check());
    if (!(edge_scale > 0) || !std::isfinite(edge_scale))
      return invalid_argument("geodesic distance: edge_scale must be > 0");
    HeatGeodesicsOptions scaled = options;
    scaled.time_factor *= edge_scale * edge_scale;  // t = time_factor * h^2 of the whole surface
    const HeatGeodesics heat(mesh, scaled);
    std::vector<std::vector<double>> out;
    for (auto source : sources) {
      out.push_back(heat.distance({source}));
      for (double x : out.back())
        if (!std::isfinite(x))
          return failed_precondition("geodesic distance: not finite everywhere (several parts?)");
    }
    return out;
  };
}

std::vector<int> nearest_vertices(const Mesh& mesh, const FaceLandmarks& landmarks) {
  std::vector<Mesh::Point> points;
  for (const auto& q : landmarks.points_mm) points.emplace_back(q[0], q[1], q[2]);
  std::vector<int> out;
  for (auto v : nearest_vertices(mesh, points)) out.push_back(v.is_valid() ? v.idx() : -1);
  return out;
}

int fill_unmapped_pixels(GeometryImage& image, const cv::Mat& filled_in) {
  cv::Mat filled = filled_in.clone();
  const cv::Mat& mask = image.domain_mask;
  int count = 0;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x)
      if (mask.at<uint8_t>(y, x) && !filled.at<uint8_t>(y, x)) ++count;
  int remaining = count;
  while (remaining > 0) {
    int progress = 0;
    cv::Mat next = filled.clone();
    for (int y = 0; y < mask.rows; ++y)
      for (int x = 0; x < mask.cols; ++x) {
        if (!mask.at<uint8_t>(y, x) || filled.at<uint8_t>(y, x)) continue;
        cv::Vec3f sum(0, 0, 0);
        float tex = 0;
        int n = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int yy = y + dy, xx = x + dx;
            if (yy < 0 || xx < 0 || yy >= mask.rows || xx >= mask.cols) continue;
            if (!filled.at<uint8_t>(yy, xx)) continue;
            sum += image.xyz_mm.at<cv::Vec3f>(yy, xx);
            if (!image.texture.empty()) tex += image.texture.at<float>(yy, xx);
            ++n;
          }
        if (n == 0) continue;
        image.xyz_mm.at<cv::Vec3f>(y, x) = sum / n;
        if (!image.texture.empty()) image.texture.at<float>(y, x) = tex / n;
        next.at<uint8_t>(y, x) = 255;
        ++progress;
      }
    filled = next;
    remaining -= progress;
    if (progress == 0) break;
  }
  return count;
}

Result<MappedFace> map_face_eip(const Mesh& mesh, const FaceLandmarks& landmarks,
                                const CanonicalDomain& domain, const DistanceFunction& distance,
                                const EipOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  const double start = thread_cpu_ms();
  double clock = start;
  auto lap = [&clock](double* ms) {
    const double now = thread_cpu_ms();
    *ms += now - clock;
    clock = now;
  };
  GVKIT_ASSIGN_OR_RETURN(FaceAnnulus annulus,
                         make_face_annulus(mesh, landmarks, distance, options.annulus));
  MappedFace out;
  lap(&out.timing.annulus_ms);
  out.timing.cut_distance_ms = annulus.distance_ms;
  if (annulus.key_names() != domain.key_names()) {
    annulus.reverse_orientation();
    if (annulus.key_names() != domain.key_names()) {
      auto joined = [](const std::vector<std::string>& names) {
        std::string text;
        for (const auto& n : names) text += (text.empty() ? "" : " ") + n;
        return text;
      };
      annulus.reverse_orientation();
      return failed_precondition(
          "boundary correspondence: the key points (eye corners, mouth, cut ends) lie in a "
          "different order on this face than on the canonical domain (face: " +
          joined(annulus.key_names()) + "; domain: " + joined(domain.key_names()) + ")");
    }
    out.warnings.push_back("mesh faces are oriented clockwise seen from the front; reversed");
  }
  GVKIT_ASSIGN_OR_RETURN(FlowCoordinates flow,
                         flow_coordinates(annulus, domain.key_u(), domain.flow().rim,
                                          domain.flow().min_cotan_weight, options.solver));
  lap(&out.timing.fields_ms);
  out.timing.laplacian_ms = flow.timing.laplacian_ms;
  out.timing.order_ms = flow.timing.order_ms;
  out.timing.f_ms = flow.timing.f_ms;
  out.timing.psi_ms = flow.timing.psi_ms;
  out.timing.correspondence_ms = flow.timing.correspondence_ms;
  out.timing.untangle_ms = flow.timing.untangle_ms;
  out.interior_extrema = flow.field_report.interior_extrema;
  out.boundary_nonmonotone = flow.boundary_nonmonotone;
  out.st_flipped = flow.flipped;
  out.st_untangled = flow.untangled_vertices;
  out.cut_method = annulus.cut_method;
  if (annulus.pinch_faces_removed > 0)
    out.warnings.push_back(std::to_string(annulus.pinch_faces_removed) +
                           " faces removed around boundary pinches (a hole touching the rim or "
                           "another hole at one vertex)");
  const TriSurface& s = annulus.surface;

  // Corner c's flow coordinates (s unwrapped per triangle).
  const auto st_of_corner = [&](int c) {
    return Eigen::Vector2d(flow.corner_s[c], flow.t[s.triangles[c / 3][c % 3]]);
  };
  std::vector<Eigen::Vector2d> st_corners(3 * s.n_triangles());
  for (int c = 0; c < 3 * s.n_triangles(); ++c) st_corners[c] = st_of_corner(c);
  const TriangleLocator locator(std::move(st_corners));

  const cv::Size size = domain.size();
  GeometryImage& image = out.image;
  image.xyz_mm = cv::Mat(size, CV_32FC3, cv::Scalar::all(0));
  const bool colours = !s.colour.empty();
  if (colours) image.texture = cv::Mat(size, CV_32F, cv::Scalar(0));
  image.domain_mask = domain.mask().clone();
  out.pixel_source.resize(size.area());
  cv::Mat filled = cv::Mat::zeros(size, CV_8U);
  // Neighbouring pixels mostly sample the same triangle: try the last one first. Without flips
  // in (s, t) the triangles (s unwrapped per triangle) do not overlap, so a triangle strictly
  // containing the point is the one the search below returns for it; with flips every pixel
  // takes the full search.
  const bool coherent = flow.flipped == 0;
  int last = -1;
  auto strictly_inside = [](const TriangleLocator::Hit& h) {
    return h.triangle >= 0 && std::min({h.barycentric[0], h.barycentric[1], h.barycentric[2]}) > 0;
  };
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      if (!image.domain_mask.at<uint8_t>(y, x)) continue;
      const Eigen::Vector2d st = domain.st(x, y);
      TriangleLocator::Hit best;
      if (coherent && last >= 0) {
        const auto hit = locator.in_triangle(last, st);
        if (strictly_inside(hit)) best = hit;
      }
      const bool in_last = best.triangle >= 0;
      double best_min = -INFINITY;
      for (double shift : {0.0, 1.0, -1.0}) {
        if (in_last) break;
        const auto hit = locator.locate({st.x() + shift, st.y()}, 1e-6);
        if (hit.triangle < 0) continue;
        const double mn = std::min({hit.barycentric[0], hit.barycentric[1], hit.barycentric[2]});
        if (mn > best_min) best_min = mn, best = hit;
        if (mn >= 0) break;
      }
      if (best.triangle < 0) continue;
      last = best.triangle;
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      float tex = 0;
      SourceWeights src;
      const auto& corners = s.triangles[best.triangle];
      src.reserve(s.source[corners[0]].size() + s.source[corners[1]].size() +
                  s.source[corners[2]].size());
      for (int j = 0; j < 3; ++j) {
        const int v = corners[j];
        const double w = std::clamp(best.barycentric[j], 0.0, 1.0);
        p += w * s.xyz[v];
        if (colours)
          tex += static_cast<float>(w) * (s.colour[v][0] + s.colour[v][1] + s.colour[v][2]) / 3.f;
        for (const auto& sw : s.source[v]) src.push_back({sw.vertex, sw.weight * w});
      }
      double wsum = 0;
      for (int j = 0; j < 3; ++j) wsum += std::clamp(best.barycentric[j], 0.0, 1.0);
      p /= wsum;
      for (auto& sw : src) sw.weight /= wsum;
      image.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(p.x(), p.y(), p.z());
      if (colours) image.texture.at<float>(y, x) = tex / static_cast<float>(wsum);
      out.pixel_source[y * size.width + x] = std::move(src);
      filled.at<uint8_t>(y, x) = 255;
    }
  out.unmapped_pixels = fill_unmapped_pixels(image, filled);
  lap(&out.timing.resample_ms);

  // Landmarks: the flow coordinates of their nearest vertex, located in D.
  std::vector<int> corner_of_input(mesh.n_vertices(), -1);
  for (int k = 0; k < s.n_triangles(); ++k)
    for (int j = 0; j < 3; ++j) {
      const auto& src = s.source[s.triangles[k][j]];
      if (src.size() == 1 && corner_of_input[src[0].vertex] < 0)
        corner_of_input[src[0].vertex] = 3 * k + j;
    }
  for (int v : nearest_vertices(mesh, landmarks)) {
    const int c = v >= 0 ? corner_of_input[v] : -1;
    if (c < 0) {
      out.landmarks_px.push_back(Eigen::Vector2d::Constant(NAN));
      continue;
    }
    const Eigen::Vector2d st = st_of_corner(c);
    out.landmarks_px.push_back(domain.pixel_of(st.x(), st.y()));
  }

  // Boundary key points: the flow coordinates of their vertex (at its first corner), located in
  // D.
  std::vector<int> vertex_corner(s.n_vertices(), -1);
  for (int c = 3 * s.n_triangles() - 1; c >= 0; --c) vertex_corner[s.triangles[c / 3][c % 3]] = c;
  for (const auto& key : annulus.keys) {
    const int v = annulus.inner_loop[key.position];
    const int c = vertex_corner[v];
    if (c >= 0 && !out.keys_px.count(key.name))
      out.keys_px[key.name] = domain.pixel_of(flow.corner_s[c], flow.t[v]);
  }

  lap(&out.timing.landmarks_ms);
  if (options.measure_quality) {
    std::vector<Eigen::Vector3d> xyz(3 * s.n_triangles());
    std::vector<Eigen::Vector2d> uv(3 * s.n_triangles());
    // The corners of a vertex differ in s by whole periods only, which pixel_of ignores: one
    // lookup per vertex.
    std::vector<int> first_corner(s.n_vertices(), -1);
    for (int k = 0; k < s.n_triangles(); ++k)
      for (int j = 0; j < 3; ++j) {
        const int v = s.triangles[k][j], c = 3 * k + j;
        xyz[c] = s.xyz[v];
        if (first_corner[v] >= 0) {
          uv[c] = uv[first_corner[v]];
        } else {
          first_corner[v] = c;
          const Eigen::Vector2d st = st_of_corner(c);
          uv[c] = domain.pixel_of(st.x(), st.y());
        }
      }
    // Counter-clockwise seen from the front is clockwise in pixels (y down): negative area.
    out.quality = measure_map_quality(xyz, uv, -1);
  }
  lap(&out.timing.quality_ms);
  out.timing.total_ms = clock - start;
  return out;
}

}  // namespace gvkit::facemap
