#pragma once
// The four boundary loops of a face mesh (outer rim, two eyes, mouth), named from landmarks, and
// the checks that a frame is usable: one genus-0 component with exactly 4 boundary loops, no
// degenerate triangles, and landmarks that touch the boundaries they name.

#include <array>
#include <vector>

#include <Eigen/Core>

#include "gvkit/core/face_landmarks.hpp"
#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

// Landmarks (iBUG numbering) that become key points on the inner boundary: the eye corners and
// the inner mouth corners. The first two anchor the cut c, which runs from 42 to 39.
inline constexpr std::array<int, 6> kBoundaryKeyLandmarks = {39, 42, 36, 45, 60, 64};

struct FaceBoundaryOptions {
  // A key landmark farther than this from the loop it names is an error (mm).
  double landmark_tolerance_mm = 15.0;
  // Triangles with a smaller area are degenerate (mm^2).
  double min_triangle_area_mm2 = 1e-10;
  Status check() const;
};

struct FaceBoundaries {
  enum Loop { kRim = 0, kEyeRight = 1, kEyeLeft = 2, kMouth = 3 };
  // Ordered vertex loops along the boundary halfedges.
  std::array<std::vector<Mesh::VertexHandle>, 4> loops;
  static int loop_of_landmark(int landmark);  // kEyeRight for 36-41, kEyeLeft 42-47, kMouth 48-67
};

// Checks the mesh and names its loops: eye loops are the nearest to landmarks 36-41 / 42-47, the
// mouth the nearest to 60-67, the rim the remaining one, which must be the longest. Fails naming
// what is wrong (boundary count, genus, degenerate triangle, landmark off its boundary).
Result<FaceBoundaries> find_face_boundaries(const Mesh& mesh, const FaceLandmarks& landmarks,
                                            const FaceBoundaryOptions& options = {});

// Closest point of a closed vertex loop to p: the index i of the loop edge (loop[i] ->
// loop[i+1]) and the parameter t along it; distance in *distance.
struct LoopPoint {
  int edge = 0;
  double t = 0;
};
LoopPoint closest_loop_point(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop,
                             const Eigen::Vector3d& p, double* distance = nullptr);

}  // namespace gvkit::facemap
