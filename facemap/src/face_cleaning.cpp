#include "gvkit/facemap/face_cleaning.hpp"

#include <chrono>
#include <utility>

namespace gvkit::facemap {

Status CleanOptions::check() const {
  GVKIT_RETURN_IF_ERROR(scan.check());
  GVKIT_RETURN_IF_ERROR(holes.check());
  if (!(landmark_max_gap_px >= 0 && landmark_max_gap_px <= 100))
    return invalid_argument("clean: landmark_max_gap_px must be in [0, 100], got " +
                            std::to_string(landmark_max_gap_px));
  return mask.check();
}

namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Fill and mask, shared by scans and meshes.
Status fill_and_mask(Mesh mesh, CleanedFace* face, const CleanOptions& options) {
  auto t = std::chrono::steady_clock::now();
  // Pinches of the scan's outer rim lie outside the face mask almost always; the mask step
  // checks the topology of what it keeps, so they are left open here.
  HoleFillingOptions hole_options = options.holes;
  hole_options.fail_on_rim_touching_holes = false;
  auto filled = fill_holes(&mesh, hole_options);
  if (!filled.is_ok()) return filled.status().with_context("hole filling");
  face->stats.holes_filled = filled->holes_filled;
  face->stats.vertices_added = filled->vertices_added;
  face->stats.fill_ms = ms_since(t);
  t = std::chrono::steady_clock::now();
  auto mask = geodesic_face_mask(mesh, face->landmarks, options.mask);
  if (!mask.is_ok()) return mask.status();
  face->stats.mask_ms = ms_since(t);
  face->stats.radius_mm = mask->radius_mm;
  face->mesh = std::move(mask->mesh);
  face->stats.output_vertices = static_cast<int>(face->mesh.n_vertices());
  face->stats.output_faces = static_cast<int>(face->mesh.n_faces());
  return Status::ok();
}

}  // namespace

Result<CleanedFace> clean_scan(const RangeScan& scan, FaceLandmarks landmarks,
                               const CleanOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  const auto start = std::chrono::steady_clock::now();
  const std::string frame = "frame " + std::to_string(scan.index);
  CleanedFace face;
  GVKIT_RETURN_IF_ERROR(
      lift_landmarks(scan, &landmarks, options.landmark_max_gap_px).with_context(frame));
  face.landmarks = std::move(landmarks);
  auto t = std::chrono::steady_clock::now();
  GVKIT_ASSIGN_OR_RETURN(ScanMesh scan_mesh, mesh_from_scan(scan, options.scan));
  face.stats.mesh_ms = ms_since(t);
  face.stats.input_vertices = static_cast<int>(scan_mesh.mesh.n_vertices());
  face.stats.input_faces = static_cast<int>(scan_mesh.mesh.n_faces());
  face.stats.repair = scan_mesh.repair.summary();
  GVKIT_RETURN_IF_ERROR(
      fill_and_mask(std::move(scan_mesh.mesh), &face, options).with_context(frame));
  face.stats.total_ms = ms_since(start);
  return face;
}

Result<CleanedFace> clean_mesh(Mesh mesh, const FaceLandmarks& landmarks, const std::string& name,
                               const CleanOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  const auto start = std::chrono::steady_clock::now();
  if (static_cast<int>(landmarks.points_mm.size()) != FaceLandmarks::kCount)
    return invalid_argument(name + ": landmarks need 68 points_mm, got " +
                            std::to_string(landmarks.points_mm.size()));
  CleanedFace face;
  face.landmarks = landmarks;
  auto t = std::chrono::steady_clock::now();
  MeshRepairOptions repair;
  repair.keep_largest_component = options.keep_largest_mesh_component;
  const MeshRepairReport report = repair_mesh(&mesh, repair);
  if (report.components > 1 && !options.keep_largest_mesh_component)
    return failed_precondition(name + ": mesh has " + std::to_string(report.components) +
                               " connected components (expected one face surface)");
  face.stats.mesh_ms = ms_since(t);
  face.stats.repair = report.summary();
  face.stats.input_vertices = static_cast<int>(mesh.n_vertices());
  face.stats.input_faces = static_cast<int>(mesh.n_faces());
  GVKIT_RETURN_IF_ERROR(fill_and_mask(std::move(mesh), &face, options).with_context(name));
  face.stats.total_ms = ms_since(start);
  return face;
}

}  // namespace gvkit::facemap
