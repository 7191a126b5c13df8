#pragma once
// IntrinsicTriangulation: a triangle mesh described by its connectivity and edge lengths (mm)
// only, so that edges can be flipped intrinsically (the flipped edge is a straight line in the
// unfolded pair of triangles, i.e. a geodesic on the original surface) without moving vertices.
// Flipping to the intrinsic Delaunay triangulation makes every cotan weight non-negative; the
// cotan Laplacian, mass matrix and per-face gradients are then built from these lengths.

#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "gvkit/core/mesh.hpp"

namespace gvkit::facemap {

class IntrinsicTriangulation {
 public:
  IntrinsicTriangulation() = default;
  // Copies the connectivity of `mesh` and measures its edge lengths. Vertex indices are kept.
  explicit IntrinsicTriangulation(const Mesh& mesh);

  // Flips every flippable non-Delaunay interior edge (opposite angles summing to more than pi)
  // until none is left. Edges whose flip would duplicate an existing edge are left alone (the
  // connectivity stays a simple mesh), so the result is Delaunay up to those rare edges.
  void flip_to_delaunay();

  const Mesh& mesh() const { return mesh_; }  // the intrinsic connectivity (positions unchanged)
  double edge_length_mm(Mesh::EdgeHandle e) const { return length_[e.idx()]; }
  double mean_edge_length_mm() const;
  int flips() const { return flips_; }

  // Positive semidefinite cotan Laplacian L (L_ii = sum of weights, L_ij = -(cot a + cot b)/2),
  // as triplets (duplicates summed by setFromTriplets).
  void cotan_laplacian(std::vector<Eigen::Triplet<double>>* triplets) const;
  // Lumped (barycentric) mass matrix: a third of the adjacent triangle areas (mm^2).
  void lumped_mass(std::vector<Eigen::Triplet<double>>* triplets) const;
  // For a per-vertex function u, adds to divergence[i] the integrated divergence at vertex i of
  // X = -grad u / |grad u| (per face), the heat method's second step. Faces with a vanishing
  // gradient contribute nothing.
  void accumulate_unit_gradient_divergence(const Eigen::VectorXd& u,
                                           Eigen::VectorXd* divergence) const;

 private:
  Mesh mesh_;
  std::vector<double> length_;  // per edge
  int flips_ = 0;
};

}  // namespace gvkit::facemap
