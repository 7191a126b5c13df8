#include "gvkit/facemap/harmonic_map_baseline.hpp"

#include <cmath>

#include "gvkit/facemap/eip_map.hpp"
#include "gvkit/facemap/harmonic_field.hpp"
#include "gvkit/facemap/map_metrics.hpp"
#include "gvkit/facemap/triangle_locator.hpp"

namespace gvkit::facemap {

Result<MappedFace> map_face_hm(const Mesh& mesh, const FaceLandmarks& landmarks, cv::Size size,
                               const HarmonicMapOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  if (size.width < 2 || size.height < 2) return invalid_argument("hm: size must be >= 2x2");
  GVKIT_ASSIGN_OR_RETURN(FaceBoundaries b,
                         find_face_boundaries(mesh, landmarks, options.boundaries));
  // The face as a TriSurface, each hole closed by a fan around its centroid.
  TriSurface s;
  const bool colours = mesh.has_vertex_colors();
  for (auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    s.xyz.emplace_back(p[0], p[1], p[2]);
    if (colours) {
      const auto& c = mesh.color(v);
      s.colour.emplace_back(c[0], c[1], c[2], c[3]);
    }
    s.source.push_back({{v.idx(), 1.0}});
  }
  for (auto f : mesh.faces()) {
    std::array<int, 3> t{};
    int k = 0;
    for (auto v : mesh.fv_range(f)) t[k++] = v.idx();
    s.triangles.push_back(t);
  }
  for (int hole : {FaceBoundaries::kEyeRight, FaceBoundaries::kEyeLeft, FaceBoundaries::kMouth}) {
    const auto& loop = b.loops[hole];
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    Eigen::Vector4f colour = Eigen::Vector4f::Zero();
    SourceWeights src;
    for (auto v : loop) {
      centre += s.xyz[v.idx()];
      if (colours) colour += s.colour[v.idx()];
      src.push_back({v.idx(), 1.0 / loop.size()});
    }
    const int c = s.n_vertices();
    s.xyz.push_back(centre / loop.size());
    if (colours) s.colour.push_back(colour / loop.size());
    s.source.push_back(src);
    for (size_t i = 0; i < loop.size(); ++i)
      s.triangles.push_back({loop[i].idx(), loop[(i + 1) % loop.size()].idx(), c});
  }
  // Rim by arc length onto the rectangle's border, from the bottom middle.
  const auto& rim = b.loops[FaceBoundaries::kRim];
  const int n_rim = static_cast<int>(rim.size());
  // Start where the line from the nose tip (30) through the chin (8) leaves the face, in the
  // frontal (x, y) plane: a fractional rim position that moves continuously with the face.
  const cv::Vec3f& nose = landmarks.points_mm[30];
  const cv::Vec3f& chin = landmarks.chin_or_lower_lip_mm();
  const Eigen::Vector2d dir = Eigen::Vector2d(chin[0] - nose[0], chin[1] - nose[1]).normalized();
  auto side = [&](Mesh::VertexHandle v) {
    const Eigen::Vector2d r(mesh.point(v)[0] - nose[0], mesh.point(v)[1] - nose[1]);
    return std::pair<double, double>(dir.x() * r.y() - dir.y() * r.x(), dir.dot(r));
  };
  int start = -1;
  double start_t = 0, best_along = -INFINITY;
  for (int i = 0; i < n_rim; ++i) {
    const auto [c0, a0] = side(rim[i]);
    const auto [c1, a1] = side(rim[(i + 1) % n_rim]);
    if ((c0 <= 0) == (c1 <= 0) || c0 == c1) continue;
    const double t = c0 / (c0 - c1);
    const double along = a0 + t * (a1 - a0);
    if (along > best_along) best_along = along, start = i, start_t = t;
  }
  if (start < 0)
    return failed_precondition(
        "hm: the line from the nose tip through the chin does not meet "
        "the rim");
  // Arc length from the start point (start_t along rim edge start -> start + 1).
  std::vector<double> arc(n_rim + 1, 0.0);
  const double first_edge = (mesh.point(rim[(start + 1) % n_rim]) - mesh.point(rim[start])).norm();
  arc[0] = 0;
  double acc = (1.0 - start_t) * first_edge;
  for (int i = 1; i <= n_rim; ++i) {
    arc[i] = acc;  // arc[i]: vertex rim[start + i]
    acc += (mesh.point(rim[(start + i + 1) % n_rim]) - mesh.point(rim[(start + i) % n_rim])).norm();
  }
  const double rim_length = arc[n_rim] + start_t * first_edge;  // back to the start point
  const double w = size.width - 1, h = size.height - 1, perimeter = 2 * (w + h);
  auto border = [&](double u) {  // u in [0, 1): bottom middle, then right, up, left, down
    double d = u * perimeter;
    if (d < w / 2) return Eigen::Vector2d(w / 2 + d, h);
    d -= w / 2;
    if (d < h) return Eigen::Vector2d(w, h - d);
    d -= h;
    if (d < w) return Eigen::Vector2d(w - d, 0);
    d -= w;
    if (d < h) return Eigen::Vector2d(0, d);
    d -= h;
    return Eigen::Vector2d(d, h);
  };
  std::vector<char> fixed(s.n_vertices(), 0);
  std::vector<double> bx(s.n_vertices(), 0), by(s.n_vertices(), 0);
  for (int i = 1; i <= n_rim; ++i) {
    const int v = rim[(start + i) % n_rim].idx();
    const Eigen::Vector2d p = border(arc[i] / rim_length);
    fixed[v] = 1, bx[v] = p.x(), by[v] = p.y();
  }
  const auto laplacian = cotan_laplacian(s);
  const std::vector<int> order = laplacian_elimination_order(laplacian);  // one for x and y
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> ux, solve_dirichlet(laplacian, fixed, bx, order));
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> uy, solve_dirichlet(laplacian, fixed, by, order));
  MappedFace out;
  out.interior_extrema = check_harmonic_field(s, laplacian, fixed, ux).interior_extrema +
                         check_harmonic_field(s, laplacian, fixed, uy).interior_extrema;
  const std::vector<int> lm_vertex = nearest_vertices(mesh, landmarks);
  if (ux[lm_vertex[36]] > ux[lm_vertex[45]])
    for (double& x : ux) x = w - x;

  std::vector<Eigen::Vector2d> uv(3 * s.n_triangles());
  std::vector<Eigen::Vector3d> xyz(3 * s.n_triangles());
  for (int k = 0; k < s.n_triangles(); ++k)
    for (int j = 0; j < 3; ++j) {
      const int v = s.triangles[k][j];
      uv[3 * k + j] = {ux[v], uy[v]};
      xyz[3 * k + j] = s.xyz[v];
    }
  // Orientation of the image: the sign of the total signed area.
  double total = 0;
  for (int k = 0; k < s.n_triangles(); ++k) {
    const Eigen::Vector2d a = uv[3 * k + 1] - uv[3 * k], c = uv[3 * k + 2] - uv[3 * k];
    total += a.x() * c.y() - a.y() * c.x();
  }
  const int orientation = total >= 0 ? 1 : -1;
  if (options.measure_quality) out.quality = measure_map_quality(xyz, uv, orientation);

  const TriangleLocator locator(uv);
  GeometryImage& image = out.image;
  image.xyz_mm = cv::Mat(size, CV_32FC3, cv::Scalar::all(0));
  if (colours) image.texture = cv::Mat(size, CV_32F, cv::Scalar(0));
  image.domain_mask = cv::Mat(size, CV_8U, cv::Scalar(255));
  out.pixel_source.resize(size.area());
  cv::Mat filled = cv::Mat::zeros(size, CV_8U);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const auto hit = locator.locate({double(x), double(y)}, 1e-6);
      if (hit.triangle < 0) continue;
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      float tex = 0;
      SourceWeights src;
      double wsum = 0;
      for (int j = 0; j < 3; ++j) {
        const int v = s.triangles[hit.triangle][j];
        const double wj = std::clamp(hit.barycentric[j], 0.0, 1.0);
        wsum += wj;
        p += wj * s.xyz[v];
        if (colours)
          tex += static_cast<float>(wj) * (s.colour[v][0] + s.colour[v][1] + s.colour[v][2]) / 3.f;
        for (const auto& sw : s.source[v]) src.push_back({sw.vertex, sw.weight * wj});
      }
      p /= wsum;
      for (auto& sw : src) sw.weight /= wsum;
      image.xyz_mm.at<cv::Vec3f>(y, x) = cv::Vec3f(p.x(), p.y(), p.z());
      if (colours) image.texture.at<float>(y, x) = tex / static_cast<float>(wsum);
      out.pixel_source[y * size.width + x] = std::move(src);
      filled.at<uint8_t>(y, x) = 255;
    }
  out.unmapped_pixels = fill_unmapped_pixels(image, filled);
  for (int v : lm_vertex)  // an absent landmark (NaN, a 51-point set's jaw) has no vertex
    out.landmarks_px.push_back(v < 0 ? Eigen::Vector2d::Constant(NAN)
                                     : Eigen::Vector2d(ux[v], uy[v]));
  return out;
}

}  // namespace gvkit::facemap
