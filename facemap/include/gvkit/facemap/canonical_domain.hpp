#pragma once
// The canonical domain D (DESIGN.md section 7): a rectangle with two eye holes and a mouth hole
// at fixed places, derived once from the ICT-FaceKit neutral face (frontal projection: the outer
// rectangle is the face's bounding box, the holes its eye and mouth boundaries) and stored as a
// small versioned JSON file (facemap/data/canonical_domain_v1.json, made by
// `gvkit facemap make-domain`). A CanonicalDomain is that spec sampled at W x H pixels and
// processed like every frame (cuts, harmonic g, flow coordinates), once per size.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "gvkit/core/ict_face_model.hpp"
#include "gvkit/core/status.hpp"
#include "gvkit/facemap/face_annulus.hpp"
#include "gvkit/facemap/flow_coordinates.hpp"
#include "gvkit/facemap/triangle_locator.hpp"

namespace gvkit::facemap {

// Normalized coordinates: x in [0, 1] left to right, y in [0, 1] top to bottom of the frontal view.
struct CanonicalDomainSpec {
  static constexpr int kVersion = 1;
  double width_mm = 0, height_mm = 0;  // the ICT neutral face's frontal bounding box
  std::vector<cv::Point2d> eye_right, eye_left, mouth;  // hole polygons
  std::vector<cv::Point2d> landmarks;                   // 68 landmarks
  std::map<int, cv::Point2d> keys;  // kBoundaryKeyLandmarks projected onto their hole boundary

  // Derived from the ICT neutral face (vertices 0..9408 and its 68 landmark vertices).
  static Result<CanonicalDomainSpec> from_ict(const IctFaceModel& model);
  static Result<CanonicalDomainSpec> read(const std::filesystem::path& path);
  // The spec shipped with gvkit (facemap/data/canonical_domain_v1.json, or the file named by
  // the environment variable GVKIT_CANONICAL_DOMAIN).
  static Result<CanonicalDomainSpec> load_default();
  Status write(const std::filesystem::path& path) const;
};

class CanonicalDomain {
 public:
  // Rasterizes the holes at size (each hole at least 3 px thick), meshes the domain pixels
  // (one vertex per pixel centre), cuts and solves it (f and psi by multigrid from
  // kMultigridMinVertices vertices on, as the frames' maps: 0.43-0.47 instead of 0.91 s at
  // 320x320). Fails when the size is too small for the holes to stay apart and manifold.
  // rim, min_cotan_weight: see flow_coordinates(); frames are mapped with the same settings.
  static Result<CanonicalDomain> create(const CanonicalDomainSpec& spec, cv::Size size,
                                        RimCorrespondence rim = RimCorrespondence::kAngle,
                                        double min_cotan_weight = kDefaultMinCotanWeight);

  cv::Size size() const { return size_; }
  const cv::Mat& mask() const { return mask_; }  // CV_8U, 255 inside D
  // Flow coordinates (s, t) of a domain pixel (x, y); NaN outside D.
  Eigen::Vector2d st(int x, int y) const { return st_[static_cast<size_t>(y) * size_.width + x]; }
  const std::map<std::string, double>& key_u() const { return flow_.key_u; }
  std::vector<std::string> key_names() const { return annulus_.key_names(); }
  // Pixel position of the canonical key points (x right, y down).
  const std::map<std::string, Eigen::Vector2d>& key_pixels() const { return key_pixels_; }
  // The point of D with flow coordinates (s, t) (s taken modulo 1), in pixels; NaN when (s, t)
  // is outside [0, 1] x [0, 1] by more than round-off.
  Eigen::Vector2d pixel_of(double s, double t) const;
  const FaceAnnulus& annulus() const { return annulus_; }
  const FlowCoordinates& flow() const { return flow_; }

 private:
  cv::Size size_;
  cv::Mat mask_;
  std::vector<Eigen::Vector2d> st_;
  FaceAnnulus annulus_;
  FlowCoordinates flow_;
  std::vector<Eigen::Vector2d> corner_pixels_;
  std::shared_ptr<TriangleLocator> st_locator_;
  std::map<std::string, Eigen::Vector2d> key_pixels_;
};

// Euclidean distance in the mesh's embedding from each source (one field per source): the
// geodesic distance on a flat domain (where the straight segment stays inside it).
// (edge_scale is not used: a DistanceFunction.)
Result<std::vector<std::vector<double>>> euclidean_distance(
    const Mesh& mesh, const std::vector<Mesh::VertexHandle>& sources, double edge_scale = 1.0);

}  // namespace gvkit::facemap
