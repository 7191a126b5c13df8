#include "gvkit/facemap/face_cleaning.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "gvkit/core/mesh_topology.hpp"
#include "gvkit/facemap/nearest_vertices.hpp"

namespace gvkit::facemap {

Status CleanOptions::check() const {
  GVKIT_RETURN_IF_ERROR(scan.check());
  GVKIT_RETURN_IF_ERROR(holes.check());
  if (!(landmark_max_gap_px >= 0 && landmark_max_gap_px <= 100))
    return invalid_argument("clean: landmark_max_gap_px must be in [0, 100], got " +
                            std::to_string(landmark_max_gap_px));
  if (!(landmark_max_snap_mm >= 0 && landmark_max_snap_mm <= 100))
    return invalid_argument("clean: landmark_max_snap_mm must be in [0, 100], got " +
                            std::to_string(landmark_max_snap_mm));
  return mask.check();
}

namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Moves required landmarks that lie off the surface to the nearest vertex (bounded).
// `shared` holds the mesh's mean edge length and nearest-vertex grid (given on to the mask).
Status snap_landmarks_to_surface(const Mesh& mesh, CleanedFace* face, const CleanOptions& options,
                                 const FaceMaskShared& shared) {
  const double mean_edge = shared.mean_edge_mm;
  const std::vector<int> required = required_landmarks();
  std::vector<Mesh::Point> targets;
  for (int i : required) {
    const cv::Vec3f& p = face->landmarks.points_mm[i];
    targets.emplace_back(p[0], p[1], p[2]);
  }
  std::vector<double> distance;
  const std::vector<Mesh::VertexHandle> nearest = shared.grid->nearest(targets, &distance);
  for (size_t k = 0; k < required.size(); ++k) {
    const double d = distance[k];
    const Mesh::Point best = mesh.point(nearest[k]);
    if (d <= 0.5 * mean_edge) continue;
    if (!(d <= options.landmark_max_snap_mm))
      return failed_precondition(
          "landmark " + std::to_string(required[k]) + " lies " +
          std::to_string(static_cast<int>(std::lround(d))) + " mm off the mesh (limit " +
          std::to_string(static_cast<int>(options.landmark_max_snap_mm)) + " mm)");
    face->landmarks.points_mm[required[k]] = cv::Vec3f(
        static_cast<float>(best[0]), static_cast<float>(best[1]), static_cast<float>(best[2]));
    ++face->stats.landmarks_snapped_mm;
    face->stats.landmark_max_snap_mm = std::max(face->stats.landmark_max_snap_mm, d);
  }
  return Status::ok();
}

// Fill and mask, shared by scans and meshes; `mesh` is filled in place, the result written to
// face->mesh. The holes in `open_holes` (eye and mouth openings) are left open for the mask to
// cut away; those the mask finds outside their contour are filled and the mask runs again, and
// on any other failure with holes open all are filled (the mask of the fully filled mesh).
Status fill_and_mask(Mesh* mesh, CleanedFace* face, const CleanOptions& options,
                     std::vector<FeatureHole> open_holes = {}) {
  auto t = std::chrono::steady_clock::now();
  // Pinches of the scan's outer rim lie outside the face mask almost always; the mask step
  // checks the topology of what it keeps, so they are left open here.
  HoleFillingOptions hole_options = options.holes;
  hole_options.fail_on_rim_touching_holes = false;
  // Openings that fill_holes would not fill anyway (touching the outer rim, or longer than
  // max_hole_edges) are not kept open as feature holes: so that the fallbacks below, which fill
  // the open holes, never fill what the reference (every hole given to fill_holes) leaves open.
  if (!open_holes.empty()) {
    const auto loops = boundary_loops(*mesh);
    size_t rim = 0;
    double rim_mm = -1.0;
    for (size_t i = 0; i < loops.size(); ++i) {
      double length = 0.0;
      for (size_t k = 0; k < loops[i].size(); ++k)
        length +=
            (mesh->point(loops[i][(k + 1) % loops[i].size()]) - mesh->point(loops[i][k])).norm();
      if (length > rim_mm) rim_mm = length, rim = i;
    }
    std::vector<char> on_rim(mesh->n_vertices(), 0);
    if (!loops.empty())
      for (auto v : loops[rim]) on_rim[v.idx()] = 1;
    std::vector<FeatureHole> kept;
    for (const FeatureHole& hole : open_holes) {
      int edges = 0;
      bool touches_rim = false;
      auto h = hole.halfedge;
      do {
        ++edges;
        touches_rim |= on_rim[mesh->from_vertex_handle(h).idx()] != 0;
        h = mesh->next_halfedge_handle(h);
      } while (h != hole.halfedge && edges <= static_cast<int>(mesh->n_halfedges()));
      const bool too_long = hole_options.max_hole_edges > 0 && edges > hole_options.max_hole_edges;
      if (!touches_rim && !too_long) kept.push_back(hole);
    }
    open_holes = std::move(kept);
  }
  std::vector<Mesh::HalfedgeHandle> left_open;
  for (const FeatureHole& hole : open_holes) left_open.push_back(hole.halfedge);
  auto filled = fill_holes(mesh, hole_options, left_open);
  if (!filled.is_ok()) return filled.status().with_context("hole filling");
  face->stats.holes_filled = filled->holes_filled;
  face->stats.vertices_added = filled->vertices_added;
  face->stats.fill_ms = ms_since(t);
  // The snapping and the first mask share the filled mesh's mean edge length and vertex grid;
  // the masks after a further fill (below) compute their own. mask_ms counts the grid and the
  // snapping.
  t = std::chrono::steady_clock::now();
  FaceMask mask;
  Status masked = Status::ok();
  {
    const NearestVertexGrid grid(*mesh);
    FaceMaskShared shared;
    shared.mean_edge_mm = mean_edge_length_mm(*mesh);
    shared.grid = &grid;
    GVKIT_RETURN_IF_ERROR(snap_landmarks_to_surface(*mesh, face, options, shared));
    masked = geodesic_face_mask(*mesh, face->landmarks, options.mask, open_holes, &mask,
                                &face->mesh, shared);
  }
  // Fills append vertices and faces, so the halfedges of the holes not yet filled stay valid.
  HoleFillingReport report;
  auto fill = [&](const FeatureHole& hole) {
    return fill_hole(mesh, hole.halfedge, hole_options, &report).with_context("hole filling");
  };
  if (!masked.is_ok() && !mask.open_holes_not_enclosed.empty()) {
    // Openings their contour does not enclose (a closed mouth's slit beside a degenerate
    // contour): fill those, keep the others open.
    std::vector<FeatureHole> still_open;
    std::vector<char> not_enclosed(open_holes.size(), 0);
    for (int i : mask.open_holes_not_enclosed) not_enclosed[i] = 1;
    for (size_t i = 0; i < open_holes.size(); ++i) {
      if (not_enclosed[i])
        GVKIT_RETURN_IF_ERROR(fill(open_holes[i]));
      else
        still_open.push_back(open_holes[i]);
    }
    open_holes = std::move(still_open);
    masked =
        geodesic_face_mask(*mesh, face->landmarks, options.mask, open_holes, &mask, &face->mesh);
  }
  if (!masked.is_ok() && !open_holes.empty()) {
    // Any other failure with holes open: every hole filled, as without open holes.
    for (const FeatureHole& hole : open_holes) GVKIT_RETURN_IF_ERROR(fill(hole));
    open_holes.clear();
    masked = geodesic_face_mask(*mesh, face->landmarks, options.mask, &mask, &face->mesh);
  }
  face->stats.holes_filled += report.holes_filled;
  face->stats.vertices_added += report.vertices_added;
  GVKIT_RETURN_IF_ERROR(masked);
  face->stats.feature_holes_open = static_cast<int>(open_holes.size());
  face->stats.mask_ms = ms_since(t);
  face->stats.radius_mm = mask.radius_mm;
  face->stats.stray_holes_filled = mask.stray_holes_filled;
  face->stats.pinch_faces_removed = mask.pinch_faces_removed;
  face->stats.cropped_vertices = mask.cropped_vertices;
  face->stats.mask_timing = mask.timing;
  face->stats.output_vertices = static_cast<int>(face->mesh.n_vertices());
  face->stats.output_faces = static_cast<int>(face->mesh.n_faces());
  return Status::ok();
}

Status clean_scan_into(const RangeScan& scan, FaceLandmarks landmarks, const CleanOptions& options,
                       CleanedFace* out) {
  GVKIT_RETURN_IF_ERROR(options.check());
  const auto start = std::chrono::steady_clock::now();
  const std::string frame = "frame " + std::to_string(scan.index);
  CleanedFace& face = *out;
  if (static_cast<int>(landmarks.points_px.size()) != FaceLandmarks::kCount)
    return invalid_argument(frame + ": landmarks: expected 68 image points, got " +
                            std::to_string(landmarks.points_px.size()));
  auto t = std::chrono::steady_clock::now();
  RangeScan skin = scan;  // shares the pixel data; only `valid` is replaced
  if (options.cut_feature_interiors)
    skin.valid =
        valid_without_feature_interiors(scan, landmarks, 0.5, &face.stats.feature_pixels_removed);
  ScanMesh scan_mesh;
  GVKIT_RETURN_IF_ERROR(mesh_from_scan(skin, options.scan, &scan_mesh));
  face.stats.mesh_ms = ms_since(t);
  // Landmarks are lifted onto the kept mesh: an inner lip over the open mouth, or an eye contour
  // over a removed eyeball, takes the nearest pixel of the lips or lids.
  const cv::Mat on_mesh = scan_mesh.vertex_of_pixel >= 0;
  LandmarkLiftReport lift;
  GVKIT_RETURN_IF_ERROR(
      lift_landmarks(scan, &landmarks, options.landmark_max_gap_px, on_mesh, &lift)
          .with_context(frame));
  face.stats.landmarks_snapped_px = lift.snapped;
  face.stats.landmark_max_snap_px = lift.max_snap_px;
  face.landmarks = std::move(landmarks);
  face.stats.input_vertices = static_cast<int>(scan_mesh.mesh.n_vertices());
  face.stats.input_faces = static_cast<int>(scan_mesh.mesh.n_faces());
  face.stats.repair = scan_mesh.repair.summary();
  std::vector<FeatureHole> open_holes;
  if (!options.fill_feature_holes && options.mask.method == GeodesicMethod::kFastMarching &&
      options.mask.eye_margin_mm > 0 && options.mask.mouth_margin_mm > 0)
    open_holes = feature_interior_holes(scan_mesh.mesh, scan_mesh.vertex_pixel, face.landmarks);
  GVKIT_RETURN_IF_ERROR(
      fill_and_mask(&scan_mesh.mesh, &face, options, std::move(open_holes)).with_context(frame));
  face.stats.total_ms = ms_since(start);
  return Status::ok();
}

Status clean_mesh_into(Mesh* mesh, const FaceLandmarks& landmarks, const std::string& name,
                       const CleanOptions& options, CleanedFace* out) {
  GVKIT_RETURN_IF_ERROR(options.check());
  const auto start = std::chrono::steady_clock::now();
  if (static_cast<int>(landmarks.points_mm.size()) != FaceLandmarks::kCount)
    return invalid_argument(name + ": landmarks need 68 points_mm, got " +
                            std::to_string(landmarks.points_mm.size()));
  CleanedFace& face = *out;
  face.landmarks = landmarks;
  auto t = std::chrono::steady_clock::now();
  MeshRepairOptions repair;
  repair.keep_largest_component = options.keep_largest_mesh_component;
  const MeshRepairReport report = repair_mesh(mesh, repair);
  if (report.components > 1 && !options.keep_largest_mesh_component)
    return failed_precondition(name + ": mesh has " + std::to_string(report.components) +
                               " connected components (expected one face surface)");
  face.stats.mesh_ms = ms_since(t);
  face.stats.repair = report.summary();
  face.stats.input_vertices = static_cast<int>(mesh->n_vertices());
  face.stats.input_faces = static_cast<int>(mesh->n_faces());
  GVKIT_RETURN_IF_ERROR(fill_and_mask(mesh, &face, options).with_context(name));
  face.stats.total_ms = ms_since(start);
  return Status::ok();
}

}  // namespace

// The results are built in place: OpenMesh meshes have no move constructor, so every move of
// one is a copy.
Result<CleanedFace> clean_scan(const RangeScan& scan, FaceLandmarks landmarks,
                               const CleanOptions& options) {
  Result<CleanedFace> result(std::in_place);
  if (Status s = clean_scan_into(scan, std::move(landmarks), options, &*result); !s.is_ok())
    result = std::move(s);
  return result;
}

Result<CleanedFace> clean_mesh(Mesh mesh, const FaceLandmarks& landmarks, const std::string& name,
                               const CleanOptions& options) {
  Result<CleanedFace> result(std::in_place);
  if (Status s = clean_mesh_into(&mesh, landmarks, name, options, &*result); !s.is_ok())
    result = std::move(s);
  return result;
}

}  // namespace gvkit::facemap
