#include "gvkit/facemap/surface_distance.hpp"

#include <array>
#include <limits>

namespace gvkit::facemap {

Mesh::Point closest_point_on_triangle(const Mesh::Point& p, const Mesh::Point& a,
                                      const Mesh::Point& b, const Mesh::Point& c) {
  const Mesh::Point ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab | ap, d2 = ac | ap;
  if (d1 <= 0 && d2 <= 0) return a;
  const Mesh::Point bp = p - b;
  const double d3 = ab | bp, d4 = ac | bp;
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Mesh::Point cp = p - c;
  const double d5 = ab | cp, d6 = ac | cp;
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

double distance_to_faces(const Mesh& mesh, const std::vector<Mesh::FaceHandle>& faces,
                         const Mesh::Point& p) {
  double best = std::numeric_limits<double>::infinity();
  for (auto f : faces) {
    std::array<Mesh::Point, 3> q;
    int k = 0;
    for (auto v : mesh.fv_range(f)) q[k++] = mesh.point(v);
    best = std::min(best, (closest_point_on_triangle(p, q[0], q[1], q[2]) - p).norm());
  }
  return best;
}

}  // namespace gvkit::facemap
