#pragma once
// Reader of the ICT-FaceKit face model (../shared/data/ict-facekit, MIT): a light-stage head in
// one topology with ARKit-style expression blendshapes. Positions are converted from the model's
// centimetres to millimetres on load. Used to make synthetic captures with exact ground truth
// (capture), geometry-video test material in the model's UV layout (codec), and meshes with known
// correspondence (facemap).

#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit {

// Parts of the model by vertex index range (README.upstream.md of the data set).
enum class IctRegion {
  kFace,           // 0-9408: genus 0 with 4 boundary loops (rim, mouth, two eyes)
  kHeadAndNeck,    // 9409-11247
  kMouthSocket,    // 11248-13293
  kEyeSocket,      // 13294-14061
  kGumsAndTongue,  // 14062-17038
  kTeeth,          // 17039-21450
  kSclera,         // 21451-22220, 23021-23790
  kIris,           // 22221-23020, 23791-24590
  kEyeExtras,      // 24591-25350: lacrimal fluid, blend and occlusion meshes
  kEyelashes,      // 25351-26718
};

class IctFaceModel {
 public:
  static constexpr int kFaceVertexCount = 9409;  // vertices 0..9408 are the face area
  static constexpr int kVertexCount = 26719;

  struct Corner {
    int vertex;    // 0-based vertex index
    int texcoord;  // 0-based index into texcoords(), -1 if none
  };
  using Polygon = std::vector<Corner>;  // 3 or 4 corners, counter-clockwise as in the file

  // Loads generic_neutral_mesh.obj and the expression OBJs named in `expressions` (all the
  // *.obj blendshape targets present in the folder when empty). Fails naming the file when one
  // is missing, malformed, or has a different vertex count.
  static Result<IctFaceModel> load(const std::filesystem::path& dir,
                                   const std::vector<std::string>& expressions = {});

  const std::vector<cv::Vec3d>& neutral_mm() const { return neutral_mm_; }
  const std::vector<Polygon>& polygons() const { return polygons_; }
  const std::vector<cv::Vec2f>& texcoords() const { return texcoords_; }  // UV in [0, 1]
  // Names of the loaded expressions (blendshape targets), sorted.
  std::vector<std::string> expression_names() const;
  bool has_expression(const std::string& name) const { return deltas_mm_.count(name) > 0; }
  // Vertex of each of the 68 iBUG landmarks (vertex_indices.json: idx_to_landmark_verts).
  const std::array<int, 68>& landmark_vertices() const { return landmark_vertices_; }

  // neutral + sum_k weight_k * (expression_k - neutral). Unknown names are a contract error.
  std::vector<cv::Vec3d> evaluate(const std::map<std::string, double>& weights) const;

  static IctRegion region_of(int vertex);

  // Triangle mesh of the polygons whose corners all satisfy keep(vertex) (quads split along the
  // shorter diagonal), with the given positions. Vertices are renumbered compactly in index
  // order; original_index (if given) receives each new vertex's model index.
  template <typename Keep>
  Mesh triangle_mesh(const std::vector<cv::Vec3d>& positions_mm, Keep keep,
                     std::vector<int>* original_index = nullptr) const;
  // The face area (vertices 0..9408) as a triangle mesh: one component, 4 boundary loops.
  Mesh face_mesh(const std::vector<cv::Vec3d>& positions_mm) const {
    return triangle_mesh(positions_mm, [](int v) { return v < kFaceVertexCount; });
  }

 private:
  std::vector<cv::Vec3d> neutral_mm_;
  std::vector<Polygon> polygons_;
  std::vector<cv::Vec2f> texcoords_;
  std::map<std::string, std::vector<cv::Vec3d>> deltas_mm_;
  std::array<int, 68> landmark_vertices_{};

  Mesh build_mesh(const std::vector<cv::Vec3d>& positions_mm, const std::vector<char>& keep,
                  std::vector<int>* original_index) const;
};

template <typename Keep>
Mesh IctFaceModel::triangle_mesh(const std::vector<cv::Vec3d>& positions_mm, Keep keep,
                                 std::vector<int>* original_index) const {
  std::vector<char> keep_vertex(positions_mm.size());
  for (size_t v = 0; v < positions_mm.size(); ++v)
    keep_vertex[v] = keep(static_cast<int>(v)) ? 1 : 0;
  return build_mesh(positions_mm, keep_vertex, original_index);
}

}  // namespace gvkit
