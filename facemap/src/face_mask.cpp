#include "gvkit/facemap/face_mask.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>

#include "gvkit/facemap/hole_filling.hpp"
#include "gvkit/facemap/level_set_clip.hpp"
#include "gvkit/facemap/mesh_repair.hpp"
#include "gvkit/facemap/nearest_vertices.hpp"
#include "gvkit/facemap/shortest_edge_path.hpp"

namespace gvkit::facemap {

Status FaceMaskOptions::check() const {
  if (radius_mm < 0 || !std::isfinite(radius_mm))
    return invalid_argument("face mask: radius must be >= 0 mm (0: automatic), got " +
                            std::to_string(radius_mm));
  if (!(radius_factor > 0.2 && radius_factor < 5.0))
    return invalid_argument("face mask: radius_factor must be in (0.2, 5), got " +
                            std::to_string(radius_factor));
  if (eye_margin_mm < 0 || mouth_margin_mm < 0)
    return invalid_argument("face mask: margins must be >= 0 mm");
  return geodesics.check();
}

namespace {

using Point = Mesh::Point;

Point to_point(const cv::Vec3f& p) { return Point(p[0], p[1], p[2]); }

template <size_t N>
std::vector<Point> contour_points(const FaceLandmarks& landmarks, const std::array<int, N>& ids) {
  std::vector<Point> out;
  for (int i : ids) out.push_back(to_point(landmarks.points_mm[i]));
  return out;
}

std::vector<Point> mouth_points(const FaceLandmarks& landmarks, MouthContour mouth) {
  return mouth == MouthContour::kInner ? contour_points(landmarks, kInnerMouthContour)
                                       : contour_points(landmarks, kOuterMouthContour);
}

// Per-mesh arrays of contour_region, kept over the three features' calls (each call leaves them
// as it found them: reset where it wrote), so that only the first call allocates and clears them.
struct ContourRegionScratch {
  explicit ContourRegionScratch(const Mesh& mesh)
      : mesh(&mesh),
        paths(mesh),
        on_path_edge(mesh.n_edges(), 0),
        in_region(mesh.n_vertices(), 0),
        component(mesh.n_faces(), -1) {}
  const Mesh* mesh;
  ShortestEdgePaths paths;
  std::vector<char> on_path_edge, in_region;
  std::vector<int> component;
};

// The vertices of the surface region enclosed by the closed edge path through `corners` (the
// vertices nearest to the contour points), the path included. A degenerate contour (a closed eye
// or mouth) encloses nothing and gives the path alone. Regions cut off from the mesh boundary by
// the path are inside, so folds under the contour (a rolled lip) are handled by connectivity, not
// by a projection.
// Boundary edges marked in `open_edge` (an eye or mouth opening left unfilled, inside the
// contour) do not count as the mesh boundary: the faces around them are enclosed as those of a
// fill would be.
std::vector<Mesh::VertexHandle> contour_region(const Mesh& mesh,
                                               const std::vector<Mesh::VertexHandle>& corners,
                                               const std::vector<char>& open_edge,
                                               ContourRegionScratch* scratch) {
  GVKIT_CHECK(scratch->mesh == &mesh, "contour region: scratch arrays of another mesh");
  // Faces outside a ball around the contour cannot be enclosed by it: they count as reaching
  // the boundary, so the flood fill of the outside stops there instead of crossing the mesh.
  Point centre(0, 0, 0);
  for (auto v : corners) centre += mesh.point(v);
  centre /= static_cast<double>(corners.size());
  double ball = 0.0;
  for (auto v : corners) ball = std::max(ball, (mesh.point(v) - centre).norm());
  ball = 2.0 * ball + 10.0;
  std::vector<char>& on_path_edge = scratch->on_path_edge;
  std::vector<char>& in_region = scratch->in_region;
  std::vector<int>& component = scratch->component;
  std::vector<int> path_edges;
  std::vector<Mesh::FaceHandle> flooded;  // every face given a component
  std::vector<Mesh::VertexHandle> region;
  auto add = [&](Mesh::VertexHandle v) {
    if (!in_region[v.idx()]) {
      in_region[v.idx()] = 1;
      region.push_back(v);
    }
  };
  ShortestEdgePaths& paths = scratch->paths;
  for (size_t k = 0; k < corners.size(); ++k) {
    const auto path = paths.path(corners[k], corners[(k + 1) % corners.size()]);
    for (size_t i = 0; i < path.size(); ++i) {
      add(path[i]);
      if (i + 1 < path.size()) {
        const auto h = mesh.find_halfedge(path[i], path[i + 1]);
        if (h.is_valid()) {
          on_path_edge[mesh.edge_handle(h).idx()] = 1;
          path_edges.push_back(mesh.edge_handle(h).idx());
        }
      }
    }
  }
  // Face components across edges that are not on the path; those that reach the mesh boundary
  // (or leave the ball) are outside. Seeds: the faces along the path (every enclosed component
  // touches it). A flood stops as soon as its component is known to be outside: at the boundary,
  // past the ball, or on a face of an earlier (outside) flood; only enclosed components are
  // flooded completely.
  std::vector<Mesh::FaceHandle> seeds, stack, members;
  for (auto v : region)
    for (auto f : mesh.vf_range(v)) seeds.push_back(f);
  int components = 0;
  for (auto f : seeds) {
    if (component[f.idx()] >= 0) continue;
    const int c = components++;
    bool outside = false;
    stack.assign(1, f);
    members.assign(1, f);
    component[f.idx()] = c;
    while (!stack.empty() && !outside) {
      const auto g = stack.back();
      stack.pop_back();
      if ((mesh.point(mesh.to_vertex_handle(mesh.halfedge_handle(g))) - centre).norm() > ball) {
        outside = true;
        break;
      }
      for (auto h : mesh.fh_range(g)) {
        const auto e = mesh.edge_handle(h);
        if (mesh.is_boundary(e)) {
          if (!open_edge.empty() && open_edge[e.idx()]) continue;
          outside = true;
          break;
        }
        if (on_path_edge[e.idx()]) continue;
        const auto n = mesh.opposite_face_handle(h);
        if (!n.is_valid()) continue;
        if (component[n.idx()] < 0) {
          component[n.idx()] = c;
          stack.push_back(n);
          members.push_back(n);
        } else if (component[n.idx()] != c) {
          outside = true;  // an earlier flood, stopped because it is outside
          break;
        }
      }
    }
    if (!outside)
      for (auto g : members)
        for (auto v : mesh.fv_range(g)) add(v);
    flooded.insert(flooded.end(), members.begin(), members.end());
  }
  for (int e : path_edges) on_path_edge[e] = 0;
  for (auto v : region) in_region[v.idx()] = 0;
  for (auto g : flooded) component[g.idx()] = -1;
  std::sort(region.begin(), region.end());
  return region;
}

// Boundary loops of the mask that are neither the rim (the longest) nor the loop nearest to an
// eye or mouth contour are gaps of the scan inside the kept skin (often pinches of the scan's
// rim that the mask moved inside); they are filled like any interior hole. Returns how many.
Result<int> fill_stray_loops(Mesh* mesh, const std::vector<Point> (&contours)[3]) {
  struct Loop {
    double length = 0.0;
    Mesh::HalfedgeHandle first;
    std::vector<Point> points;
  };
  std::vector<Loop> loops;
  std::vector<char> visited(mesh->n_halfedges(), 0);
  for (auto h : mesh->halfedges()) {
    if (!mesh->is_boundary(h) || visited[h.idx()]) continue;
    Loop loop;
    loop.first = h;
    auto l = h;
    do {
      visited[l.idx()] = 1;
      loop.length += mesh->calc_edge_length(l);
      loop.points.push_back(mesh->point(mesh->from_vertex_handle(l)));
      l = mesh->next_halfedge_handle(l);
    } while (l != h && !visited[l.idx()]);
    loops.push_back(std::move(loop));
  }
  if (loops.size() <= 4) return 0;
  std::vector<char> keep(loops.size(), 0);
  keep[std::max_element(loops.begin(), loops.end(),
                        [](const Loop& a, const Loop& b) { return a.length < b.length; }) -
       loops.begin()] = 1;
  for (const auto& contour : contours) {
    size_t best = 0;
    double best_d = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < loops.size(); ++i) {
      if (keep[i]) continue;
      double sum = 0.0;
      for (const auto& p : contour) {
        double d2 = std::numeric_limits<double>::infinity();
        for (const auto& q : loops[i].points) d2 = std::min(d2, (p - q).sqrnorm());
        sum += std::sqrt(d2);
      }
      if (sum < best_d) best_d = sum, best = i;
    }
    keep[best] = 1;
  }
  HoleFillingOptions options;
  HoleFillingReport report;
  int filled = 0;
  for (size_t i = 0; i < loops.size(); ++i) {
    if (keep[i]) continue;
    GVKIT_RETURN_IF_ERROR(fill_hole(mesh, loops[i].first, options, &report));
    ++filled;
  }
  return filled;
}

std::string describe(const MeshTopology& t) {
  std::string loops;
  for (int n : t.boundary_loop_lengths) loops += (loops.empty() ? "" : ", ") + std::to_string(n);
  return std::to_string(t.components) + " component(s), genus " + std::to_string(t.genus) + ", " +
         std::to_string(t.boundary_loops) + " boundary loop(s)" +
         (loops.empty() ? "" : " of " + loops + " edges");
}

}  // namespace

double mean_edge_length_mm(const Mesh& mesh) {
  double sum = 0.0;
  for (auto e : mesh.edges()) sum += mesh.calc_edge_length(e);
  return sum / std::max<size_t>(mesh.n_edges(), 1);
}

double default_mask_radius_mm(const FaceLandmarks& landmarks, double radius_factor) {
  Point eyes(0, 0, 0), mouth(0, 0, 0);
  for (int i = 36; i < 48; ++i) eyes += to_point(landmarks.points_mm[i]);
  for (int i = 48; i < 68; ++i) mouth += to_point(landmarks.points_mm[i]);
  return radius_factor * (eyes / 12.0 - mouth / 20.0).norm();
}

std::vector<Mesh::VertexHandle> feature_source_vertices(const Mesh& mesh,
                                                        const FaceLandmarks& landmarks,
                                                        MouthContour mouth) {
  std::vector<Point> points = contour_points(landmarks, kRightEyeContour);
  for (const auto& p : contour_points(landmarks, kLeftEyeContour)) points.push_back(p);
  for (const auto& p : mouth_points(landmarks, mouth)) points.push_back(p);
  std::vector<Mesh::VertexHandle> out = nearest_vertices(mesh, points);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

Result<FaceMask> geodesic_face_mask(const Mesh& mesh, const FaceLandmarks& landmarks,
                                    const FaceMaskOptions& options) {
  Result<FaceMask> result(std::in_place);
  if (Status s = geodesic_face_mask(mesh, landmarks, options, &*result, &result->mesh); !s.is_ok())
    result = std::move(s);
  return result;
}

Status geodesic_face_mask(const Mesh& mesh, const FaceLandmarks& landmarks,
                          const FaceMaskOptions& options, FaceMask* info, Mesh* masked) {
  return geodesic_face_mask(mesh, landmarks, options, {}, info, masked);
}

Status geodesic_face_mask(const Mesh& mesh, const FaceLandmarks& landmarks,
                          const FaceMaskOptions& options,
                          const std::vector<FeatureHole>& open_holes, FaceMask* info, Mesh* masked,
                          const FaceMaskShared& shared) {
  GVKIT_RETURN_IF_ERROR(options.check());
  if (!open_holes.empty() && options.method != GeodesicMethod::kFastMarching)
    return invalid_argument("face mask: open eye and mouth holes need fast marching geodesics");
  if (!open_holes.empty() && !(options.eye_margin_mm > 0 && options.mouth_margin_mm > 0))
    return invalid_argument("face mask: open eye and mouth holes need margins > 0 mm");
  // Per open hole its boundary vertices; per feature the edges of its open holes.
  std::vector<std::vector<Mesh::VertexHandle>> open_hole_vertices;
  std::vector<char> open_edge[3];
  for (const FeatureHole& hole : open_holes) {
    GVKIT_CHECK(hole.feature >= 0 && hole.feature < 3, "face mask: open hole feature not 0..2");
    GVKIT_CHECK(hole.halfedge.is_valid() &&
                    hole.halfedge.idx() < static_cast<int>(mesh.n_halfedges()) &&
                    mesh.is_boundary(hole.halfedge),
                "face mask: open hole halfedge is not on the mesh boundary");
    std::vector<char>& edges = open_edge[hole.feature];
    if (edges.empty()) edges.assign(mesh.n_edges(), 0);
    std::vector<Mesh::VertexHandle>& vertices = open_hole_vertices.emplace_back();
    auto h = hole.halfedge;
    do {
      edges[mesh.edge_handle(h).idx()] = 1;
      vertices.push_back(mesh.to_vertex_handle(h));
      h = mesh.next_halfedge_handle(h);
    } while (h != hole.halfedge);
  }
  if (static_cast<int>(landmarks.points_mm.size()) != FaceLandmarks::kCount)
    return invalid_argument("face mask: expected 68 landmarks in mm, got " +
                            std::to_string(landmarks.points_mm.size()));
  FaceMask& result = *info;
  result.timing = {};
  result.stray_holes_filled = 0;
  result.pinch_faces_removed = 0;
  result.open_holes_not_enclosed.clear();
  auto step_start = std::chrono::steady_clock::now();
  auto lap = [&step_start](double* ms) {
    const auto now = std::chrono::steady_clock::now();
    *ms = std::chrono::duration<double, std::milli>(now - step_start).count();
    step_start = now;
  };
  result.radius_mm = options.radius_mm > 0
                         ? options.radius_mm
                         : default_mask_radius_mm(landmarks, options.radius_factor);
  const double radius = result.radius_mm;

  const double mean_edge =
      shared.mean_edge_mm >= 0 ? shared.mean_edge_mm : mean_edge_length_mm(mesh);
  const std::vector<Point> contours[] = {contour_points(landmarks, kRightEyeContour),
                                         contour_points(landmarks, kLeftEyeContour),
                                         mouth_points(landmarks, options.mouth_contour)};
  // Every feature landmark must lie on the surface. The nearest vertices to the required
  // landmarks and to the contour points come from one pass over the mesh.
  std::vector<Mesh::VertexHandle> corners[3];
  {
    const std::vector<int> required = required_landmarks();
    std::vector<Point> points;
    for (int i : required) points.push_back(to_point(landmarks.points_mm[i]));
    for (const auto& contour : contours)
      points.insert(points.end(), contour.begin(), contour.end());
    std::vector<double> d;
    GVKIT_CHECK(!shared.grid || &shared.grid->mesh() == &mesh,
                "face mask: the shared nearest-vertex grid is not this mesh's");
    const std::vector<Mesh::VertexHandle> nearest =
        shared.grid ? shared.grid->nearest(points, &d) : nearest_vertices(mesh, points, &d);
    for (size_t k = 0; k < required.size(); ++k)
      if (d[k] > std::max(5.0, 4.0 * mean_edge))
        return failed_precondition("landmark " + std::to_string(required[k]) + " lies " +
                                   std::to_string(static_cast<int>(d[k])) + " mm off the mesh");
    size_t next = required.size();
    for (int k = 0; k < 3; ++k)
      for (size_t i = 0; i < contours[k].size(); ++i) corners[k].push_back(nearest[next++]);
  }

  // Heat method: crop to the Euclidean ball of radius R (+ a margin) around the sources first,
  // as a geodesic ball lies inside the Euclidean one. Fast marching needs no crop: its queries
  // stop at the radius. A mesh wholly inside the ball is used as it is (no copy).
  Mesh clipped;
  bool crop_mesh = false;
  if (options.method == GeodesicMethod::kHeat) {
    std::vector<Point> source_points = contour_points(landmarks, kRightEyeContour);
    for (const auto& p : contour_points(landmarks, kLeftEyeContour)) source_points.push_back(p);
    for (const auto& p : mouth_points(landmarks, options.mouth_contour)) source_points.push_back(p);
    const double crop = radius + 3.0 * mean_edge;
    std::vector<double> outside(mesh.n_vertices());
    double farthest = 0.0;
    for (auto v : mesh.vertices()) {
      double d2 = std::numeric_limits<double>::infinity();
      for (const auto& s : source_points) d2 = std::min(d2, (mesh.point(v) - s).sqrnorm());
      outside[v.idx()] = std::sqrt(d2);
      farthest = std::max(farthest, outside[v.idx()]);
    }
    if (farthest > crop) {
      LevelSetClipOptions crop_options;
      crop_options.level = crop;
      crop_options.snap = 0.0;
      clipped = clip_mesh_below(mesh, outside, crop_options);
      crop_mesh = true;
    }
  }
  const Mesh& cropped = crop_mesh ? clipped : mesh;
  result.cropped_vertices = static_cast<int>(cropped.n_vertices());
  if (cropped.n_faces() == 0) return failed_precondition("face mask: nothing within the radius");
  lap(&result.timing.crop_ms);

  // The eye and mouth regions on the crop, first: an open hole that its contour does not
  // enclose ends the call before any distance is computed.
  std::vector<Mesh::VertexHandle> regions[3];
  std::vector<Mesh::VertexHandle> all_features;
  ContourRegionScratch region_scratch(cropped);
  for (int k = 0; k < 3; ++k) {
    regions[k] =
        contour_region(cropped, crop_mesh ? nearest_vertices(cropped, contours[k]) : corners[k],
                       open_edge[k], &region_scratch);
    all_features.insert(all_features.end(), regions[k].begin(), regions[k].end());
  }
  {
    std::vector<char> in_region[3];
    for (size_t i = 0; i < open_holes.size(); ++i) {
      const int k = open_holes[i].feature;
      if (in_region[k].empty()) {
        in_region[k].assign(cropped.n_vertices(), 0);
        for (auto v : regions[k]) in_region[k][v.idx()] = 1;
      }
      for (auto v : open_hole_vertices[i])
        if (!in_region[k][v.idx()]) {
          result.open_holes_not_enclosed.push_back(static_cast<int>(i));
          break;
        }
    }
    if (!result.open_holes_not_enclosed.empty())
      return failed_precondition(
          "face mask: " + std::to_string(result.open_holes_not_enclosed.size()) +
          " open hole(s) not enclosed by their contour (first: " +
          std::to_string(open_hole_vertices[result.open_holes_not_enclosed.front()].size()) +
          " edges, feature " +
          std::to_string(open_holes[result.open_holes_not_enclosed.front()].feature) + ")");
  }
  lap(&result.timing.regions_ms);

  // Their geodesic distances, and the distance from all three. Heat: one factorisation serves
  // the four queries. Fast marching: the regions' queries stop a few edges past their margins;
  // the distance from all three is their minimum.
  std::unique_ptr<HeatGeodesics> heat;
  std::unique_ptr<FastMarching> marching;
  if (options.method == GeodesicMethod::kHeat)
    heat = std::make_unique<HeatGeodesics>(cropped, options.geodesics);
  else
    marching = std::make_unique<FastMarching>(cropped);
  lap(&result.timing.factor_ms);
  const double margins[] = {options.eye_margin_mm, options.eye_margin_mm, options.mouth_margin_mm};
  // Keep f <= 0 with f = max(d_features - R, margin_k - d_k): inside the radius and outside the
  // grown eye and mouth regions; one level-set cut gives all four boundaries.
  std::vector<double> f(cropped.n_vertices(), -std::numeric_limits<double>::infinity());
  if (heat) {
    for (int k = 0; k < 3; ++k) {
      const std::vector<double> d = heat->distance(regions[k]);
      for (size_t i = 0; i < f.size(); ++i) f[i] = std::max(f[i], margins[k] - d[i]);
    }
    const std::vector<double> d_features = heat->distance(all_features);
    for (size_t i = 0; i < f.size(); ++i) f[i] = std::max(f[i], d_features[i] - radius);
  } else {
    const std::vector<double> d_features =
        marching->distance(all_features, radius + 3.0 * mean_edge);
    result.cropped_vertices = static_cast<int>(
        std::count_if(d_features.begin(), d_features.end(), [](double d) { return d < 1e300; }));
    for (size_t i = 0; i < f.size(); ++i) f[i] = std::max(f[i], d_features[i] - radius);
    // The regions' queries reach few vertices; elsewhere margin_k - d_k is -infinity and
    // leaves f as it is.
    for (int k = 0; k < 3; ++k)
      for (const auto& [v, d] : marching->reached(regions[k], margins[k] + 3.0 * mean_edge))
        f[v] = std::max(f[v], margins[k] - d);
  }
  lap(&result.timing.distances_ms);
  LevelSetClipOptions clip;
  clip.level = 0.0;
  if (!crop_mesh) clip.snap = 0.1 * mean_edge;  // the default, known already
  // An open hole disappears with the region only when none of its boundary edges is kept.
  for (const auto& vertices : open_hole_vertices)
    for (auto v : vertices)
      if (!(f[v.idx()] > clip.snap))
        return failed_precondition("face mask: an open hole of " + std::to_string(vertices.size()) +
                                   " edges would stay in the mask");
  clip_mesh_below(cropped, f, clip, masked);
  lap(&result.timing.clip_ms);

  // A rim that touches itself or a gap at one vertex passes the counts below (the vertex is
  // traced as two loops and counted once), but is no surface facemap map can cut.
  result.pinch_faces_removed = open_boundary_pinches(masked);
  result.topology = mesh_topology(*masked);
  if (options.fill_stray_holes && result.topology.components == 1 &&
      result.topology.boundary_loops > 4) {
    auto filled = fill_stray_loops(masked, contours);
    if (!filled.is_ok()) return filled.status().with_context("face mask: stray hole");
    result.stray_holes_filled = *filled;
    result.topology = mesh_topology(*masked);
  }
  const MeshTopology& t = result.topology;
  if (t.components != 1 || t.genus != 0 || t.boundary_loops != 4)
    return failed_precondition("face mask (radius " + std::to_string(static_cast<int>(radius)) +
                               " mm): found " + describe(t) +
                               "; expected 1 component, genus 0, 4 boundary loops");
  // What facemap map refuses: triangles without area (a fill or a cut gone flat).
  int degenerate = 0;
  for (auto face : masked->faces()) degenerate += !(masked->calc_face_area(face) > 1e-10);
  if (degenerate > 0)
    return failed_precondition("face mask: " + std::to_string(degenerate) +
                               " degenerate triangle(s) (area <= 1e-10 mm^2)");
  lap(&result.timing.check_ms);
  return Status::ok();
}

}  // namespace gvkit::facemap
