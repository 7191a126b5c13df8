#pragma once
// Multi-source geodesic distance on a triangle mesh by the heat method (Crane, Weischedel and
// Wardetzky 2013): diffuse heat from the sources for a short time t, normalise its gradient, and
// integrate the unit field back with a Poisson solve. The operators are built from edge lengths
// only, optionally on the intrinsic Delaunay triangulation of the mesh (edge flips that keep the
// vertex set and the surface), which keeps the cotan weights positive on poor meshes.
//
// HeatGeodesics factorises both systems once in its constructor; distance() then costs two
// back-substitutions per query, so one object serves many queries on the same mesh.

#include <memory>
#include <vector>

#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

enum class SparseSolverKind {
  kCholmod,         // simplicial Cholesky of SuiteSparse CHOLMOD (AMD ordering; supernodal needs a
                    // tuned BLAS, which the reference BLAS here is not)
  kSimplicialLdlt,  // Eigen's SimplicialLDLT: the plain reference
};

struct HeatGeodesicsOptions {
  // Diffusion time t = time_factor * h^2, h = mean edge length (the paper's choice is 1).
  double time_factor = 1.0;
  // Rebuild the cotan operators on the intrinsic Delaunay triangulation (by edge flips).
  bool intrinsic_delaunay = true;
  // On meshes with boundary, average the Neumann and Dirichlet heat solutions (the paper's
  // recommendation; better near the rim, one more factorisation). Sources on the boundary see
  // Neumann only, since a Dirichlet solution vanishes there.
  bool average_boundary_conditions = false;
  SparseSolverKind solver = SparseSolverKind::kCholmod;

  Status check() const;
};

class HeatGeodesics {
 public:
  // Builds and factorises the operators. Preconditions (contract errors): a triangle mesh with
  // at least one face and no degenerate face (zero-length edge). Vertices not in any face get
  // distance infinity. A mesh with several components gives infinity on components without a
  // source.
  explicit HeatGeodesics(const Mesh& mesh, const HeatGeodesicsOptions& options = {});
  ~HeatGeodesics();
  HeatGeodesics(HeatGeodesics&&) noexcept;
  HeatGeodesics& operator=(HeatGeodesics&&) noexcept;

  // Geodesic distance (mm) from the nearest source to every vertex, indexed by vertex idx();
  // 0 at the sources. Sources must be valid vertices of the mesh (contract). Empty sources give
  // infinity everywhere.
  std::vector<double> distance(const std::vector<Mesh::VertexHandle>& sources) const;

  // Number of edge flips made to reach the intrinsic Delaunay triangulation.
  int intrinsic_flips() const;
  // Diffusion time t (mm^2) in use.
  double time_mm2() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gvkit::facemap
