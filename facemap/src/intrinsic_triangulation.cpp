#include "gvkit/facemap/intrinsic_triangulation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>

namespace gvkit::facemap {

namespace {

// Area of a triangle from its side lengths (Kahan's stable Heron); 0 when degenerate.
double triangle_area(double a, double b, double c) {
  std::array<double, 3> s{a, b, c};
  std::sort(s.begin(), s.end(), std::greater<>());
  const double x = s[0], y = s[1], z = s[2];
  const double p = (x + (y + z)) * (z - (x - y)) * (z + (x - y)) * (x + (y - z));
  return p > 0.0 ? 0.25 * std::sqrt(p) : 0.0;
}

// Cotangent of the angle opposite side c in a triangle with sides a, b, c.
double cotan_opposite(double a, double b, double c, double area) {
  const double safe_area = std::max(area, 1e-12 * (a * a + b * b + c * c));
  return (a * a + b * b - c * c) / (4.0 * safe_area);
}

// The three halfedges of a face and the lengths of their edges.
struct FaceSides {
  std::array<Mesh::HalfedgeHandle, 3> h;
  std::array<double, 3> l;
};

}  // namespace

IntrinsicTriangulation::IntrinsicTriangulation(const Mesh& mesh) {
  mesh_.reserve(mesh.n_vertices(), mesh.n_edges(), mesh.n_faces());
  for (auto v : mesh.vertices()) mesh_.add_vertex(mesh.point(v));
  for (auto f : mesh.faces()) {
    std::array<Mesh::VertexHandle, 3> fv;
    int k = 0;
    for (auto v : mesh.fv_range(f)) fv[k++] = v;
    mesh_.add_face(fv[0], fv[1], fv[2]);
  }
  length_.resize(mesh_.n_edges());
  for (auto e : mesh_.edges()) length_[e.idx()] = mesh_.calc_edge_length(e);
}

double IntrinsicTriangulation::mean_edge_length_mm() const {
  if (length_.empty()) return 0.0;
  double sum = 0.0;
  for (double l : length_) sum += l;
  return sum / static_cast<double>(length_.size());
}

void IntrinsicTriangulation::flip_to_delaunay() {
  auto face_sides = [&](Mesh::HalfedgeHandle h0) {
    FaceSides s;
    s.h = {h0, mesh_.next_halfedge_handle(h0), mesh_.prev_halfedge_handle(h0)};
    for (int k = 0; k < 3; ++k) s.l[k] = length_[mesh_.edge_handle(s.h[k]).idx()];
    return s;
  };
  // Sum of the cotangents of the two angles opposite e (>= 0 iff Delaunay).
  auto cotan_sum = [&](Mesh::EdgeHandle e) {
    double sum = 0.0;
    for (int side = 0; side < 2; ++side) {
      const auto h = mesh_.halfedge_handle(e, side);
      const FaceSides s = face_sides(h);
      sum += cotan_opposite(s.l[1], s.l[2], s.l[0], triangle_area(s.l[0], s.l[1], s.l[2]));
    }
    return sum;
  };

  std::deque<Mesh::EdgeHandle> queue;
  std::vector<char> queued(mesh_.n_edges(), 1);
  for (auto e : mesh_.edges()) queue.push_back(e);
  while (!queue.empty()) {
    const auto e = queue.front();
    queue.pop_front();
    queued[e.idx()] = 0;
    if (mesh_.is_boundary(e)) continue;
    if (cotan_sum(e) >= -1e-10) continue;
    if (!mesh_.is_flip_ok(e)) continue;

    // Unfold the two triangles on the edge (i -> j) into the plane: i at the origin, j on +x,
    // k above (face of h0), l below (face of h1); the new edge is |k - l|.
    const auto h0 = mesh_.halfedge_handle(e, 0);
    const auto h1 = mesh_.halfedge_handle(e, 1);
    const FaceSides a = face_sides(h0);  // h0: i->j, then j->k, k->i
    const FaceSides b = face_sides(h1);  // h1: j->i, then i->l, l->j
    const double lij = a.l[0];
    const double ljk = a.l[1], lki = a.l[2];
    const double lil = b.l[1], llj = b.l[2];
    const double kx = (lij * lij + lki * lki - ljk * ljk) / (2.0 * lij);
    const double ky = std::sqrt(std::max(0.0, lki * lki - kx * kx));
    const double lx = (lij * lij + lil * lil - llj * llj) / (2.0 * lij);
    const double ly = -std::sqrt(std::max(0.0, lil * lil - lx * lx));
    const double new_length = std::hypot(kx - lx, ky - ly);

    const std::array<Mesh::EdgeHandle, 4> around{
        mesh_.edge_handle(a.h[1]), mesh_.edge_handle(a.h[2]), mesh_.edge_handle(b.h[1]),
        mesh_.edge_handle(b.h[2])};
    mesh_.flip(e);
    length_[e.idx()] = new_length;
    ++flips_;
    for (auto n : around)
      if (!queued[n.idx()]) {
        queued[n.idx()] = 1;
        queue.push_back(n);
      }
  }
}

void IntrinsicTriangulation::cotan_laplacian(std::vector<Eigen::Triplet<double>>* triplets) const {
  triplets->clear();
  triplets->reserve(mesh_.n_faces() * 9);
  for (auto f : mesh_.faces()) {
    const auto h0 = mesh_.halfedge_handle(f);
    const std::array<Mesh::HalfedgeHandle, 3> h{h0, mesh_.next_halfedge_handle(h0),
                                                mesh_.prev_halfedge_handle(h0)};
    std::array<double, 3> l;
    for (int k = 0; k < 3; ++k) l[k] = length_[mesh_.edge_handle(h[k]).idx()];
    const double area = triangle_area(l[0], l[1], l[2]);
    for (int k = 0; k < 3; ++k) {
      // Halfedge h[k] is opposite the corner between h[k+1] and h[k+2].
      const double w = 0.5 * cotan_opposite(l[(k + 1) % 3], l[(k + 2) % 3], l[k], area);
      const int i = mesh_.from_vertex_handle(h[k]).idx();
      const int j = mesh_.to_vertex_handle(h[k]).idx();
      triplets->emplace_back(i, j, -w);
      triplets->emplace_back(j, i, -w);
      triplets->emplace_back(i, i, w);
      triplets->emplace_back(j, j, w);
    }
  }
}

void IntrinsicTriangulation::lumped_mass(std::vector<Eigen::Triplet<double>>* triplets) const {
  triplets->clear();
  triplets->reserve(mesh_.n_faces() * 3);
  for (auto f : mesh_.faces()) {
    std::array<double, 3> l;
    int k = 0;
    for (auto h : mesh_.fh_range(f)) l[k++] = length_[mesh_.edge_handle(h).idx()];
    const double third = triangle_area(l[0], l[1], l[2]) / 3.0;
    for (auto v : mesh_.fv_range(f)) triplets->emplace_back(v.idx(), v.idx(), third);
  }
}

void IntrinsicTriangulation::accumulate_unit_gradient_divergence(
    const Eigen::VectorXd& u, Eigen::VectorXd* divergence) const {
  for (auto f : mesh_.faces()) {
    const auto h0 = mesh_.halfedge_handle(f);
    const auto h1 = mesh_.next_halfedge_handle(h0);
    const auto h2 = mesh_.next_halfedge_handle(h1);
    // Corners i -> j -> k counter-clockwise: i at the origin, j on +x, k above.
    const int i = mesh_.from_vertex_handle(h0).idx();
    const int j = mesh_.to_vertex_handle(h0).idx();
    const int k = mesh_.to_vertex_handle(h1).idx();
    const double lij = length_[mesh_.edge_handle(h0).idx()];
    const double ljk = length_[mesh_.edge_handle(h1).idx()];
    const double lki = length_[mesh_.edge_handle(h2).idx()];
    const double area = triangle_area(lij, ljk, lki);
    if (area <= 0.0) continue;
    const Eigen::Vector2d pi(0.0, 0.0), pj(lij, 0.0);
    const double kx = (lij * lij + lki * lki - ljk * ljk) / (2.0 * lij);
    const Eigen::Vector2d pk(kx, std::sqrt(std::max(0.0, lki * lki - kx * kx)));
    // grad u = sum_c u_c * rot90(opposite edge) / (2A), rot90(x, y) = (-y, x).
    auto rot = [](const Eigen::Vector2d& e) { return Eigen::Vector2d(-e.y(), e.x()); };
    const Eigen::Vector2d grad =
        (u[i] * rot(pk - pj) + u[j] * rot(pi - pk) + u[k] * rot(pj - pi)) / (2.0 * area);
    const double norm = grad.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) continue;
    const Eigen::Vector2d x = -grad / norm;
    const double cot_i = cotan_opposite(lij, lki, ljk, area);
    const double cot_j = cotan_opposite(lij, ljk, lki, area);
    const double cot_k = cotan_opposite(ljk, lki, lij, area);
    // div at corner c: 1/2 (cot(opposite e1) e1.X + cot(opposite e2) e2.X), e = edges out of c.
    (*divergence)[i] += 0.5 * (cot_k * (pj - pi).dot(x) + cot_j * (pk - pi).dot(x));
    (*divergence)[j] += 0.5 * (cot_i * (pk - pj).dot(x) + cot_k * (pi - pj).dot(x));
    (*divergence)[k] += 0.5 * (cot_j * (pi - pk).dot(x) + cot_i * (pj - pk).dot(x));
  }
}

}  // namespace gvkit::facemap
