#include "gvkit/facemap/level_set_clip.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

Mesh clip_mesh_below(const Mesh& mesh, const std::vector<double>& f,
                     const LevelSetClipOptions& options, MeshRepairReport* report,
                     std::vector<int>* source_vertex) {
  Mesh out;
  clip_mesh_below(mesh, f, options, &out, report, source_vertex);
  return out;
}

void clip_mesh_below(const Mesh& mesh, const std::vector<double>& f_in,
                     const LevelSetClipOptions& options, Mesh* out, MeshRepairReport* report,
                     std::vector<int>* source_vertex) {
  GVKIT_CHECK(f_in.size() == mesh.n_vertices(), "clip: one value per vertex");
  const double level = options.level;
  double snap = options.snap;
  if (snap < 0) {
    double sum = 0.0;
    for (auto e : mesh.edges()) sum += mesh.calc_edge_length(e);
    snap = 0.1 * sum / std::max<size_t>(mesh.n_edges(), 1);
  }
  std::vector<double> f(f_in);
  for (double& x : f)
    if (std::abs(x - level) < snap) x = level;

  const bool colors = mesh.has_vertex_colors();
  std::vector<Mesh::Point> points;
  std::vector<Mesh::Color> point_colors;
  std::vector<int> point_source;
  points.reserve(mesh.n_vertices());
  if (colors) point_colors.reserve(mesh.n_vertices());
  point_source.reserve(mesh.n_vertices());
  std::vector<int> point_of_vertex(mesh.n_vertices(), -1);
  std::map<std::pair<int, int>, int> point_of_edge;
  auto vertex_point = [&](Mesh::VertexHandle v) {
    int& p = point_of_vertex[v.idx()];
    if (p < 0) {
      p = static_cast<int>(points.size());
      points.push_back(mesh.point(v));
      if (colors) point_colors.push_back(mesh.color(v));
      point_source.push_back(v.idx());
    }
    return p;
  };
  auto edge_point = [&](Mesh::VertexHandle a, Mesh::VertexHandle b) {
    const std::pair<int, int> key(std::min(a.idx(), b.idx()), std::max(a.idx(), b.idx()));
    auto it = point_of_edge.find(key);
    if (it != point_of_edge.end()) return it->second;
    const double fa = f[a.idx()], fb = f[b.idx()];
    const double t = std::isinf(fb) ? 0.0 : (level - fa) / (fb - fa);  // fa < level < fb or back
    const double s = std::isinf(fa) ? 1.0 : t;
    const int p = static_cast<int>(points.size());
    points.push_back(mesh.point(a) + (mesh.point(b) - mesh.point(a)) * s);
    if (colors)
      point_colors.push_back(mesh.color(a) +
                             (mesh.color(b) - mesh.color(a)) * static_cast<float>(s));
    point_source.push_back(-1);
    point_of_edge.emplace(key, p);
    return p;
  };

  std::vector<std::array<int, 3>> triangles;
  triangles.reserve(mesh.n_faces());
  for (auto face : mesh.faces()) {
    std::array<Mesh::VertexHandle, 3> v;
    int k = 0;
    for (auto w : mesh.fv_range(face)) v[k++] = w;
    int inside = 0, strictly_inside = 0;
    for (auto w : v) {
      inside += f[w.idx()] <= level;
      strictly_inside += f[w.idx()] < level;
    }
    if (inside == 3) {
      triangles.push_back({vertex_point(v[0]), vertex_point(v[1]), vertex_point(v[2])});
      continue;
    }
    if (strictly_inside == 0) continue;
    // Sutherland-Hodgman against f <= level.
    std::vector<int> poly;
    for (int i = 0; i < 3; ++i) {
      const auto a = v[i], b = v[(i + 1) % 3];
      const double fa = f[a.idx()], fb = f[b.idx()];
      if (fa <= level) poly.push_back(vertex_point(a));
      if ((fa < level && fb > level) || (fa > level && fb < level))
        poly.push_back(fa < level ? edge_point(a, b) : edge_point(b, a));
    }
    if (poly.size() == 3) {
      triangles.push_back({poly[0], poly[1], poly[2]});
    } else if (poly.size() == 4) {
      // Split along the shorter diagonal.
      if ((points[poly[0]] - points[poly[2]]).sqrnorm() <=
          (points[poly[1]] - points[poly[3]]).sqrnorm()) {
        triangles.push_back({poly[0], poly[1], poly[2]});
        triangles.push_back({poly[0], poly[2], poly[3]});
      } else {
        triangles.push_back({poly[0], poly[1], poly[3]});
        triangles.push_back({poly[1], poly[2], poly[3]});
      }
    }
  }
  MeshRepairOptions repair;
  repair.keep_largest_component = options.keep_largest_component;
  // Two triangles with the same corners would need two input faces on the same three points
  // (a vertex pair and a point on their edge: collinear, dropped as degenerate).
  repair.check_duplicates = false;
  std::vector<int> original;
  mesh_from_triangles(points, point_colors, triangles, repair, out, report, &original);
  if (source_vertex) {
    source_vertex->resize(original.size());
    for (size_t i = 0; i < original.size(); ++i) (*source_vertex)[i] = point_source[original[i]];
  }
}

}  // namespace gvkit::facemap
