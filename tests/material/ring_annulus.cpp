#include "ring_annulus.hpp"

#include <cmath>

namespace gvkit::testing {

Eigen::Vector3d planar_ring_position(int ring, int sector, int rings, int sectors) {
  const double r = 1.0 + 2.0 * ring / (rings - 1), phi = 2 * M_PI * sector / sectors;
  return {r * std::cos(phi), r * std::sin(phi), 0.0};
}

facemap::FaceAnnulus ring_annulus(int rings, int sectors, const RingPosition& position) {
  facemap::FaceAnnulus a;
  facemap::TriSurface& s = a.surface;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < sectors; ++j) {
      s.xyz.push_back(position ? position(i, j) : planar_ring_position(i, j, rings, sectors));
      s.source.push_back({{static_cast<int>(s.xyz.size()) - 1, 1.0}});
      s.uncut_vertex.push_back(static_cast<int>(s.xyz.size()) - 1);
    }
  auto id = [&](int i, int j) { return i * sectors + (j % sectors); };
  for (int i = 0; i + 1 < rings; ++i)
    for (int j = 0; j < sectors; ++j) {
      s.triangles.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      s.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
    }
  for (const auto& loop : facemap::tri_surface_boundary_loops(s)) {
    if (s.xyz[loop[0]].norm() < 2)
      a.inner_loop = loop;
    else
      a.outer_loop = loop;
  }
  return a;
}

}  // namespace gvkit::testing
