#include "gvkit/facemap/face_annulus.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <queue>
#include <set>
#include <string>
#include <utility>

#include "gvkit/facemap/mesh_cutting.hpp"
#include "gvkit/facemap/mesh_repair.hpp"
#include "thread_cpu_time.hpp"

namespace gvkit::facemap {
namespace {

const char* kCMid = "c_mid";
const char* kDEnd = "d_end";
const char* kNose = "30";

// Places the key points on inner_loop: names "<key>#<k>" in loop order starting at "36#0".
Status locate_keys(FaceAnnulus& a, const std::vector<std::pair<std::string, int>>& key_uncut) {
  std::multimap<int, std::string> uncut_to_name;
  for (const auto& [name, v] : key_uncut) uncut_to_name.emplace(v, name);
  std::vector<std::pair<int, std::string>> found;  // (position, base name)
  for (int i = 0; i < static_cast<int>(a.inner_loop.size()); ++i) {
    auto range = uncut_to_name.equal_range(a.surface.uncut_vertex[a.inner_loop[i]]);
    for (auto it = range.first; it != range.second; ++it) found.emplace_back(i, it->second);
  }
  int anchor = -1, anchors = 0;
  for (const auto& [pos, name] : found)
    if (name == "36") anchor = pos, ++anchors;
  if (anchors != 1)
    return failed_precondition("face annulus: landmark 36 is not on the inner boundary once");
  const int n = static_cast<int>(a.inner_loop.size());
  std::rotate(a.inner_loop.begin(), a.inner_loop.begin() + anchor, a.inner_loop.end());
  for (auto& f : found) f.first = (f.first - anchor + n) % n;
  std::sort(found.begin(), found.end());
  std::map<std::string, int> count;
  a.keys.clear();
  for (const auto& [pos, name] : found)
    a.keys.push_back({name + "#" + std::to_string(count[name]++), pos});
  return Status::ok();
}

std::vector<char> loop_flags(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop) {
  std::vector<char> flags(mesh.n_vertices(), 0);
  for (auto v : loop) flags[v.idx()] = 1;
  return flags;
}

bool touches(const Mesh& mesh, const SurfacePoint& p, const std::vector<char>& loop) {
  if (loop.empty()) return false;
  if (p.is_vertex()) return loop[p.vertex.idx()] != 0;
  return mesh.is_boundary(mesh.edge_handle(p.halfedge)) &&
         loop[mesh.from_vertex_handle(p.halfedge).idx()] &&
         loop[mesh.to_vertex_handle(p.halfedge).idx()];
}

// Traces a cut from start to target (on their loops; start_loop empty for an interior start)
// and trims the ends that run along those loops, so only the path's ends touch a boundary. On a
// pixel-grid domain the steepest descent may first follow the jagged hole boundary.
Result<std::vector<SurfacePoint>> trace_cut(const Mesh& mesh, const std::vector<double>& field,
                                            Mesh::VertexHandle start,
                                            const std::vector<char>& target,
                                            const std::vector<char>& start_loop,
                                            const std::vector<char>& target_loop,
                                            const DescentPathOptions& options,
                                            bool slide_along_start) {
  auto may_touch = [&](Mesh::VertexHandle v) {
    return (slide_along_start && !start_loop.empty() && start_loop[v.idx()]) ||
           target_loop[v.idx()];
  };
  GVKIT_ASSIGN_OR_RETURN(std::vector<SurfacePoint> path,
                         trace_descent_path(mesh, field, start, target, options, may_touch));
  size_t i = 0, j = path.size() - 1;
  while (i + 1 < path.size() && touches(mesh, path[i + 1], start_loop)) ++i;
  while (j > i + 1 && touches(mesh, path[j - 1], target_loop)) --j;
  for (size_t k = i + 1; k < j; ++k)
    if (touches(mesh, path[k], start_loop) || touches(mesh, path[k], target_loop))
      return failed_precondition("face annulus: a cut touches a hole boundary twice");
  if (j <= i) return failed_precondition("face annulus: a cut has no length");
  return std::vector<SurfacePoint>(path.begin() + static_cast<std::ptrdiff_t>(i),
                                   path.begin() + static_cast<std::ptrdiff_t>(j) + 1);
}

}  // namespace

Status FaceAnnulusOptions::check() const {
  GVKIT_RETURN_IF_ERROR(boundaries.check());
  GVKIT_RETURN_IF_ERROR(path.check());
  if (!(key_snap_fraction >= 0 && key_snap_fraction <= 0.5))
    return invalid_argument("face annulus: key_snap_fraction must be in [0, 0.5]");
  if (!(distance_crop_mm >= 0) || !std::isfinite(distance_crop_mm))
    return invalid_argument("face annulus: distance_crop_mm must be >= 0 (0: whole mesh)");
  return Status::ok();
}

std::vector<std::string> FaceAnnulus::key_names() const {
  std::vector<std::string> names;
  for (const auto& k : keys) names.push_back(k.name);
  return names;
}

void FaceAnnulus::reverse_orientation() {
  for (auto& t : surface.triangles) std::swap(t[1], t[2]);
  std::reverse(outer_loop.begin(), outer_loop.end());
  std::reverse(inner_loop.begin() + 1, inner_loop.end());
  GVKIT_CHECK(locate_keys(*this, key_vertices_uncut).is_ok());
}

namespace {

// Fails when a path (before insertion) visits a vertex or crosses an edge twice, or touches a
// flagged vertex or edge after its start (an earlier cut it must not run into or cross).
Status check_path(const Mesh& mesh, const std::vector<SurfacePoint>& path,
                  const std::vector<char>& forbidden_vertex,
                  const std::vector<char>& forbidden_edge, const std::string& what) {
  std::set<int> vertices, edges;
  for (size_t i = 0; i < path.size(); ++i) {
    const SurfacePoint& p = path[i];
    if (p.is_vertex()) {
      if (!vertices.insert(p.vertex.idx()).second)
        return failed_precondition("face annulus: the cut " + what + " visits a vertex twice");
      if (i > 0 && !forbidden_vertex.empty() && forbidden_vertex[p.vertex.idx()])
        return failed_precondition("face annulus: the cut " + what + " runs into the other cut");
    } else {
      const int e = mesh.edge_handle(p.halfedge).idx();
      if (!edges.insert(e).second)
        return failed_precondition("face annulus: the cut " + what + " crosses an edge twice");
      if (!forbidden_edge.empty() && e < static_cast<int>(forbidden_edge.size()) &&
          forbidden_edge[e])
        return failed_precondition("face annulus: the cut " + what + " crosses the other cut");
    }
  }
  return Status::ok();
}

// Shortest path along edges (Euclidean edge lengths) from start to goal through vertices not
// flagged in blocked (goal may be flagged). first_step, when not empty, flags the vertices the
// path may take as its first step. Fails when goal cannot be reached.
Result<std::vector<SurfacePoint>> shortest_edge_path(const Mesh& mesh, Mesh::VertexHandle start,
                                                     Mesh::VertexHandle goal,
                                                     const std::vector<char>& blocked,
                                                     const std::vector<char>& first_step,
                                                     const std::string& what) {
  const int n = static_cast<int>(mesh.n_vertices());
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::vector<int> parent(n, -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  dist[start.idx()] = 0;
  queue.emplace(0.0, start.idx());
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    if (v == goal.idx()) break;
    const Mesh::VertexHandle vh(v);
    for (auto h : mesh.voh_range(vh)) {
      const Mesh::VertexHandle w = mesh.to_vertex_handle(h);
      if (w != goal && blocked[w.idx()]) continue;
      if (mesh.is_boundary(mesh.edge_handle(h))) continue;
      if (vh == start && !first_step.empty() && !first_step[w.idx()]) continue;
      const double nd = d + (mesh.point(w) - mesh.point(vh)).norm();
      if (nd < dist[w.idx()]) dist[w.idx()] = nd, parent[w.idx()] = v, queue.emplace(nd, w.idx());
    }
  }
  if (!std::isfinite(dist[goal.idx()]))
    return failed_precondition("face annulus: no edge path for the cut " + what);
  std::vector<SurfacePoint> path;
  for (int v = goal.idx(); v >= 0; v = parent[v]) {
    SurfacePoint p;
    p.vertex = Mesh::VertexHandle(v);
    path.push_back(p);
  }
  std::reverse(path.begin(), path.end());
  return path;
}

// The neighbours of v (on the cut c, between c's neighbours prev and next) on the side of the
// nearest one to `toward`: the side a cut from v toward that point must leave c on.
std::vector<char> side_of_cut(const Mesh& mesh, Mesh::VertexHandle v, Mesh::VertexHandle prev,
                              Mesh::VertexHandle next, const Mesh::Point& toward) {
  std::vector<Mesh::VertexHandle> ring;
  for (auto w : mesh.vv_range(v)) ring.push_back(w);
  const int n = static_cast<int>(ring.size());
  const int ip = static_cast<int>(std::find(ring.begin(), ring.end(), prev) - ring.begin());
  const int in = static_cast<int>(std::find(ring.begin(), ring.end(), next) - ring.begin());
  std::vector<char> flags(mesh.n_vertices(), 0);
  if (ip == n || in == n) return flags;
  // The two arcs strictly between prev and next in ring order.
  std::array<std::vector<Mesh::VertexHandle>, 2> arcs;
  for (int k = (ip + 1) % n; k != in; k = (k + 1) % n) arcs[0].push_back(ring[k]);
  for (int k = (in + 1) % n; k != ip; k = (k + 1) % n) arcs[1].push_back(ring[k]);
  double best = std::numeric_limits<double>::infinity();
  int side = 0;
  for (int a = 0; a < 2; ++a)
    for (auto w : arcs[a]) {
      const double d = (mesh.point(w) - toward).norm();
      if (d < best) best = d, side = a;
    }
  for (auto w : arcs[side]) flags[w.idx()] = 1;
  return flags;
}

// The vertex of the boundary loop at lp: an end of lp's edge when lp lies within snap (edge
// parameter) of it, otherwise a new vertex splitting the edge, inserted into loop.
Mesh::VertexHandle loop_vertex_at(CuttableMesh& cm, std::vector<Mesh::VertexHandle>& loop,
                                  const LoopPoint& lp, double snap) {
  const int n = static_cast<int>(loop.size());
  if (lp.t <= snap) return loop[lp.edge];
  if (lp.t >= 1.0 - snap) return loop[(lp.edge + 1) % n];
  const auto h = cm.mesh.find_halfedge(loop[lp.edge], loop[(lp.edge + 1) % n]);
  GVKIT_CHECK(h.is_valid() && cm.mesh.is_boundary(h));
  const Mesh::VertexHandle v = split_edge_at(cm, h, lp.t);
  loop.insert(loop.begin() + lp.edge + 1, v);
  return v;
}

// A boundary key: the landmark projected onto its loop, as a vertex (splitting the boundary
// edge there unless a vertex is within snap of it).
Mesh::VertexHandle boundary_key_vertex(CuttableMesh& cm, std::vector<Mesh::VertexHandle>& loop,
                                       const cv::Vec3f& q, double snap) {
  const LoopPoint lp = closest_loop_point(cm.mesh, loop, Eigen::Vector3d(q[0], q[1], q[2]));
  return loop_vertex_at(cm, loop, lp, snap);
}

// The closest point to q on the loop's edges first_edge, first_edge + 1, ... (count of them,
// wrapping), with its distance.
std::pair<LoopPoint, double> closest_arc_point(const Mesh& mesh,
                                               const std::vector<Mesh::VertexHandle>& loop,
                                               int first_edge, int count, const cv::Vec3f& q) {
  const int n = static_cast<int>(loop.size());
  const Eigen::Vector3d p(q[0], q[1], q[2]);
  std::pair<LoopPoint, double> best{{}, std::numeric_limits<double>::infinity()};
  for (int k = 0; k < count; ++k) {
    const int e = (first_edge + k) % n;
    const auto& a0 = mesh.point(loop[e]);
    const auto& b0 = mesh.point(loop[(e + 1) % n]);
    const Eigen::Vector3d a(a0[0], a0[1], a0[2]), b(b0[0], b0[1], b0[2]);
    const double t =
        std::clamp((p - a).dot(b - a) / std::max((b - a).squaredNorm(), 1e-300), 0.0, 1.0);
    const double d = (a + t * (b - a) - p).norm();
    if (d < best.second) best = {{e, t}, d};
  }
  return best;
}

// d's end: the middle of the upper lip (62) on the mouth boundary's upper arc between the
// corners (60, 64). The upper arc is the one that fits 62 on it and 66 (the middle of the lower
// lip) on the other best; a plain nearest point can fall on the lower lip when the mouth hole is a
// thin slit (a closed mouth), which puts the cut on the wrong side of the corners.
Mesh::VertexHandle upper_lip_vertex(CuttableMesh& cm, std::vector<Mesh::VertexHandle>& loop,
                                    Mesh::VertexHandle corner_a, Mesh::VertexHandle corner_b,
                                    const FaceLandmarks& landmarks, double snap) {
  const int n = static_cast<int>(loop.size());
  const int ia = static_cast<int>(std::find(loop.begin(), loop.end(), corner_a) - loop.begin());
  const int ib = static_cast<int>(std::find(loop.begin(), loop.end(), corner_b) - loop.begin());
  GVKIT_CHECK(ia < n && ib < n, "mouth corners lie on the mouth loop");
  const int count_ab = (ib - ia + n) % n, count_ba = n - count_ab;
  const auto up_ab = closest_arc_point(cm.mesh, loop, ia, count_ab, landmarks.points_mm[62]);
  const auto up_ba = closest_arc_point(cm.mesh, loop, ib, count_ba, landmarks.points_mm[62]);
  const auto low_ab = closest_arc_point(cm.mesh, loop, ia, count_ab, landmarks.points_mm[66]);
  const auto low_ba = closest_arc_point(cm.mesh, loop, ib, count_ba, landmarks.points_mm[66]);
  const LoopPoint lp =
      up_ab.second + low_ba.second <= up_ba.second + low_ab.second ? up_ab.first : up_ba.first;
  return loop_vertex_at(cm, loop, lp, snap);
}

std::vector<char> flags_of(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& vertices) {
  std::vector<char> flags(mesh.n_vertices(), 0);
  for (auto v : vertices) flags[v.idx()] = 1;
  return flags;
}

std::vector<char> edges_of(const Mesh& mesh,
                           const std::vector<const std::vector<Mesh::VertexHandle>*>& paths) {
  std::vector<char> flags(mesh.n_edges(), 0);
  for (const auto* path : paths)
    for (size_t i = 1; i < path->size(); ++i) {
      const auto h = mesh.find_halfedge((*path)[i - 1], (*path)[i]);
      GVKIT_CHECK(h.is_valid(), "consecutive path vertices share an edge");
      flags[mesh.edge_handle(h).idx()] = 1;
    }
  return flags;
}

// The edges of a mesh as plain arrays (neighbours of vertex v at [offset[v], offset[v + 1]),
// with their lengths), for the Dijkstra searches that choose the crop below.
struct EdgeGraph {
  std::vector<int> offset, neighbour;
  std::vector<double> length;
  explicit EdgeGraph(const Mesh& mesh) {
    const int n = static_cast<int>(mesh.n_vertices());
    offset.assign(n + 1, 0);
    for (auto h : mesh.halfedges()) ++offset[mesh.from_vertex_handle(h).idx() + 1];
    for (int v = 0; v < n; ++v) offset[v + 1] += offset[v];
    neighbour.resize(offset[n]);
    length.resize(offset[n]);
    std::vector<int> fill(offset.begin(), offset.end() - 1);
    for (auto h : mesh.halfedges()) {
      const auto a = mesh.from_vertex_handle(h), b = mesh.to_vertex_handle(h);
      neighbour[fill[a.idx()]] = b.idx();
      length[fill[a.idx()]++] = (mesh.point(b) - mesh.point(a)).norm();
    }
  }
  // Dijkstra from sources (distance 0) up to max_distance, or until stop is settled (>= 0).
  // Returns the distances (infinity where not reached) and the parents.
  void search(const std::vector<int>& sources, double max_distance, int stop,
              std::vector<double>* dist, std::vector<int>* parent) const {
    const int n = static_cast<int>(offset.size()) - 1;
    dist->assign(n, std::numeric_limits<double>::infinity());
    parent->assign(n, -1);
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
    for (int s : sources) (*dist)[s] = 0, queue.emplace(0.0, s);
    while (!queue.empty()) {
      const auto [d, v] = queue.top();
      queue.pop();
      if (d > (*dist)[v]) continue;
      if (v == stop) return;
      for (int i = offset[v]; i < offset[v + 1]; ++i) {
        const int w = neighbour[i];
        const double nd = d + length[i];
        if (nd < (*dist)[w] && nd <= max_distance)
          (*dist)[w] = nd, (*parent)[w] = v, queue.emplace(nd, w);
      }
    }
  }
};

// The distance fields from `sources` that the descent cuts follow, solved on the part of the
// mesh within crop_mm (along edges) of the shortest edge paths between the given pairs of
// vertices (the routes the cuts take) instead of the whole face: the heat method's cost is its
// factorizations, and the cuts need the fields only near their routes. A geodesic between two
// points stays close to the shortest edge path between them. The diffusion time is the whole
// mesh's (edge_scale); the heat method's result still depends a little on the mesh's border
// everywhere, which moves the cuts by 0.1-1 mm on main-job frames. Outside the crop the fields
// are a large value (the descent never goes there). crop_mm <= 0, or a crop whose largest piece
// does not hold every source, solves on the whole mesh.
Result<std::vector<std::vector<double>>> cut_distance_fields(
    const Mesh& mesh, const std::vector<Mesh::VertexHandle>& sources,
    const std::vector<std::pair<Mesh::VertexHandle, Mesh::VertexHandle>>& routes,
    const DistanceFunction& distance, double crop_mm) {
  if (crop_mm <= 0) return distance(mesh, sources, 1.0);
  const int n = static_cast<int>(mesh.n_vertices());
  const EdgeGraph graph(mesh);
  std::vector<double> dist;
  std::vector<int> parent;
  std::vector<int> on_routes;
  for (const auto& [a, b] : routes) {
    graph.search({a.idx()}, std::numeric_limits<double>::infinity(), b.idx(), &dist, &parent);
    if (!std::isfinite(dist[b.idx()])) return distance(mesh, sources, 1.0);
    for (int v = b.idx(); v >= 0; v = parent[v]) on_routes.push_back(v);
  }
  graph.search(on_routes, crop_mm, -1, &dist, &parent);
  std::vector<int> point_of_vertex(n, -1);
  std::vector<Mesh::Point> points;
  std::vector<int> vertex_of_point;
  std::vector<std::array<int, 3>> triangles;
  for (auto f : mesh.faces()) {
    std::array<int, 3> t{};
    int k = 0;
    bool inside = true;
    for (auto v : mesh.fv_range(f)) {
      inside = inside && std::isfinite(dist[v.idx()]);
      t[k++] = v.idx();
    }
    if (!inside) continue;
    for (int& v : t) {
      if (point_of_vertex[v] < 0) {
        point_of_vertex[v] = static_cast<int>(points.size());
        points.push_back(mesh.point(Mesh::VertexHandle(v)));
        vertex_of_point.push_back(v);
      }
      v = point_of_vertex[v];
    }
    triangles.push_back(t);
  }
  std::vector<int> original;
  MeshRepairReport report;
  const Mesh crop = mesh_from_triangles(points, {}, triangles, {}, &report, &original);
  std::vector<int> crop_vertex(n, -1);
  for (size_t i = 0; i < original.size(); ++i)
    crop_vertex[vertex_of_point[original[i]]] = static_cast<int>(i);
  std::vector<Mesh::VertexHandle> crop_sources;
  for (auto s : sources) {
    if (crop_vertex[s.idx()] < 0) return distance(mesh, sources, 1.0);
    crop_sources.emplace_back(crop_vertex[s.idx()]);
  }
  auto mean_edge = [](const Mesh& m) {
    double sum = 0;
    for (auto e : m.edges()) sum += m.calc_edge_length(e);
    return sum / static_cast<double>(std::max<size_t>(m.n_edges(), 1));
  };
  GVKIT_ASSIGN_OR_RETURN(std::vector<std::vector<double>> crop_fields,
                         distance(crop, crop_sources, mean_edge(mesh) / mean_edge(crop)));
  std::vector<std::vector<double>> fields;
  for (const auto& cf : crop_fields) {
    double outside = 0;
    for (double x : cf) outside = std::max(outside, x);
    outside = 10.0 * outside + 1e3;
    std::vector<double> f(n, outside);
    for (int v = 0; v < n; ++v)
      if (crop_vertex[v] >= 0) f[v] = cf[crop_vertex[v]];
    fields.push_back(std::move(f));
  }
  return fields;
}

// One attempt at the annulus, with the cuts traced as descent paths or as edge paths.
Result<FaceAnnulus> build_annulus(const Mesh& mesh, const std::vector<int>& original,
                                  const FaceLandmarks& landmarks, FaceBoundaries boundaries,
                                  const DistanceFunction& distance,
                                  const FaceAnnulusOptions& options, bool edge_paths,
                                  double crop_mm) {
  CuttableMesh cm(mesh, &original);
  auto boundary_flags = [&] {
    std::vector<char> flags(cm.mesh.n_vertices(), 0);
    for (auto v : cm.mesh.vertices())
      if (cm.mesh.is_boundary(v)) flags[v.idx()] = 1;
    return flags;
  };

  // Key landmarks projected onto their loops, as vertices (splitting boundary edges).
  std::map<int, Mesh::VertexHandle> key_vertex;
  for (int lm : kBoundaryKeyLandmarks) {
    auto& loop = boundaries.loops[FaceBoundaries::loop_of_landmark(lm)];
    const Mesh::VertexHandle v =
        boundary_key_vertex(cm, loop, landmarks.points_mm[lm], options.key_snap_fraction);
    for (const auto& [other, ov] : key_vertex)
      if (ov == v)
        return failed_precondition("landmarks " + std::to_string(other) + " and " +
                                   std::to_string(lm) + " land on the same boundary point");
    key_vertex[lm] = v;
  }
  // d's end: the middle of the upper lip (62) on the upper arc of the mouth boundary.
  std::vector<Mesh::VertexHandle>& mouth_loop = boundaries.loops[FaceBoundaries::kMouth];
  const Mesh::VertexHandle lip = upper_lip_vertex(cm, mouth_loop, key_vertex[60], key_vertex[64],
                                                  landmarks, options.key_snap_fraction);
  if (lip == key_vertex[60] || lip == key_vertex[64])
    return failed_precondition("landmark 62 lands on a mouth corner of the mouth boundary");

  // The interior vertex nearest to a landmark, off the flagged vertices (none when empty).
  auto nearest_interior = [&](int landmark, const std::vector<char>& avoid) {
    const cv::Vec3f& q = landmarks.points_mm[landmark];
    const Mesh::Point p(q[0], q[1], q[2]);
    double best = std::numeric_limits<double>::infinity();
    Mesh::VertexHandle out;
    for (auto v : cm.mesh.vertices()) {
      if (cm.mesh.is_boundary(v) || (!avoid.empty() && avoid[v.idx()])) continue;
      const double dd = (cm.mesh.point(v) - p).sqrnorm();
      if (dd < best) best = dd, out = v;
    }
    return out;
  };
  // The points the cuts run through, and (for descent paths) their distance fields, solved once
  // on the uncut mesh and carried along every edge split as linear interpolation (exact for the
  // piecewise-linear field the descent follows).
  const Mesh::VertexHandle bridge = nearest_interior(27, {});
  const Mesh::VertexHandle nose = nearest_interior(30, {});
  if (!bridge.is_valid() || !nose.is_valid() || bridge == nose)
    return failed_precondition("face annulus: no separate vertices for landmarks 27 and 30");
  enum Field { kToBridge = 0, kTo39 = 1, kToNose = 2, kToLip = 3 };
  if (!edge_paths) {
    GVKIT_ASSIGN_OR_RETURN(
        std::vector<std::vector<double>> fields,
        cut_distance_fields(
            cm.mesh, {bridge, key_vertex[39], nose, lip},
            {{key_vertex[42], bridge}, {bridge, key_vertex[39]}, {bridge, nose}, {nose, lip}},
            distance, crop_mm));
    GVKIT_CHECK(fields.size() == 4, "one distance field per source");
    for (const auto& f : fields) cm.add_field(f);
  }
  const std::vector<char> left_eye =
      loop_flags(cm.mesh, boundaries.loops[FaceBoundaries::kEyeLeft]);
  const std::vector<char> right_eye =
      loop_flags(cm.mesh, boundaries.loops[FaceBoundaries::kEyeRight]);

  // c: from the left inner eye corner (42) to the right one (39), through the top of the nose
  // bridge (27) unless c_through_nose_bridge is off.
  std::vector<Mesh::VertexHandle> c;
  Mesh::VertexHandle mid;
  size_t mid_index = 0;
  if (options.c_through_nose_bridge) {
    std::vector<SurfacePoint> c1_points, c2_points;
    if (edge_paths) {
      GVKIT_ASSIGN_OR_RETURN(c1_points, shortest_edge_path(cm.mesh, key_vertex[42], bridge,
                                                           boundary_flags(), {}, "c (from 42)"));
    } else {
      const std::vector<double> to_bridge = cm.field(kToBridge);
      std::vector<char> is_bridge(cm.mesh.n_vertices(), 0);
      is_bridge[bridge.idx()] = 1;
      GVKIT_ASSIGN_OR_RETURN(c1_points,
                             trace_cut(cm.mesh, to_bridge, key_vertex[42], is_bridge, left_eye,
                                       std::vector<char>(cm.mesh.n_vertices(), 0), options.path,
                                       options.slide_along_start));
    }
    GVKIT_RETURN_IF_ERROR(check_path(cm.mesh, c1_points, {}, {}, "c (from 42)"));
    c = insert_path(cm, c1_points);
    if (c.size() < 2) return failed_precondition("face annulus: the cut from 42 is empty");
    const std::vector<char> on_c1 = flags_of(cm.mesh, c);
    if (edge_paths) {
      std::vector<char> blocked = boundary_flags();
      for (size_t i = 0; i < blocked.size(); ++i) blocked[i] |= on_c1[i];
      GVKIT_ASSIGN_OR_RETURN(
          c2_points, shortest_edge_path(cm.mesh, bridge, key_vertex[39], blocked, {}, "c (to 39)"));
    } else {
      const std::vector<double> to_39 = cm.field(kTo39);
      std::vector<char> is_39(cm.mesh.n_vertices(), 0);
      is_39[key_vertex[39].idx()] = 1;
      GVKIT_ASSIGN_OR_RETURN(
          c2_points,
          trace_cut(cm.mesh, to_39, bridge, is_39, {},
                    loop_flags(cm.mesh, boundaries.loops[FaceBoundaries::kEyeRight]),  // sized now
                    options.path, false));
    }
    GVKIT_RETURN_IF_ERROR(
        check_path(cm.mesh, c2_points, on_c1, edges_of(cm.mesh, {&c}), "c (to 39)"));
    const std::vector<Mesh::VertexHandle> c2 = insert_path(cm, c2_points);
    if (c2.size() < 2) return failed_precondition("face annulus: the cut to 39 is empty");
    mid = bridge;
    mid_index = c.size() - 1;
    c.insert(c.end(), c2.begin() + 1, c2.end());
    key_vertex[42] = c.front();
    key_vertex[39] = c.back();
  } else {
    std::vector<SurfacePoint> c_points;
    if (edge_paths) {
      GVKIT_ASSIGN_OR_RETURN(c_points, shortest_edge_path(cm.mesh, key_vertex[42], key_vertex[39],
                                                          boundary_flags(), {}, "c"));
    } else {
      const std::vector<double> to_39 = cm.field(kTo39);
      std::vector<char> is_39(cm.mesh.n_vertices(), 0);
      is_39[key_vertex[39].idx()] = 1;
      GVKIT_ASSIGN_OR_RETURN(c_points,
                             trace_cut(cm.mesh, to_39, key_vertex[42], is_39, left_eye, right_eye,
                                       options.path, options.slide_along_start));
    }
    GVKIT_RETURN_IF_ERROR(check_path(cm.mesh, c_points, {}, {}, "c"));
    c = insert_path(cm, c_points);
    if (c.size() < 2) return failed_precondition("face annulus: the cut between the eyes is empty");
    // Where the trimmed cut meets the eyes is where the keys 42 and 39 are from now on.
    key_vertex[42] = c.front();
    key_vertex[39] = c.back();

    // The middle of c by arc length: an existing path vertex, or a split of the edge there.
    std::vector<double> arc(c.size(), 0.0);
    for (size_t i = 1; i < c.size(); ++i)
      arc[i] = arc[i - 1] + (cm.mesh.point(c[i]) - cm.mesh.point(c[i - 1])).norm();
    const double half = 0.5 * arc.back();
    size_t seg = 0;
    while (seg + 2 < c.size() && arc[seg + 1] < half) ++seg;
    const double seg_len = arc[seg + 1] - arc[seg];
    const double t = seg_len > 0 ? (half - arc[seg]) / seg_len : 0.5;
    if (t < 0.25 && seg > 0) {
      mid = c[seg], mid_index = seg;
    } else if (t > 0.75 && seg + 2 < c.size()) {
      mid = c[seg + 1], mid_index = seg + 1;
    } else {
      const auto h = cm.mesh.find_halfedge(c[seg], c[seg + 1]);
      GVKIT_CHECK(h.is_valid(), "consecutive path vertices share an edge");
      mid = split_edge_at(cm, h, t);
      c.insert(c.begin() + static_cast<std::ptrdiff_t>(seg) + 1, mid);
      mid_index = seg + 1;
    }
  }
  if (mid_index == 0 || mid_index + 1 >= c.size())
    return failed_precondition("face annulus: the middle of c is an end of c");

  // The nose tip: the vertex nearest to landmark 30 off the boundaries and off c.
  if (flags_of(cm.mesh, c)[nose.idx()])
    return failed_precondition("face annulus: the cut c runs through the nose tip");

  // d, first part: from the middle of c to the nose tip, on the side of c facing the nose.
  std::vector<SurfacePoint> d1_points;
  if (edge_paths) {
    std::vector<char> blocked = boundary_flags();
    for (auto v : c) blocked[v.idx()] = 1;
    const std::vector<char> side =
        side_of_cut(cm.mesh, mid, c[mid_index - 1], c[mid_index + 1], cm.mesh.point(nose));
    GVKIT_ASSIGN_OR_RETURN(
        d1_points, shortest_edge_path(cm.mesh, mid, nose, blocked, side, "d (to the nose)"));
  } else {
    const std::vector<double> to_nose = cm.field(kToNose);
    std::vector<char> is_nose(cm.mesh.n_vertices(), 0);
    is_nose[nose.idx()] = 1;
    GVKIT_ASSIGN_OR_RETURN(d1_points,
                           trace_descent_path(cm.mesh, to_nose, mid, is_nose, options.path));
  }
  GVKIT_RETURN_IF_ERROR(check_path(cm.mesh, d1_points, flags_of(cm.mesh, c),
                                   edges_of(cm.mesh, {&c}), "d (to the nose)"));
  std::vector<Mesh::VertexHandle> d = insert_path(cm, d1_points);
  if (d.size() < 2) return failed_precondition("face annulus: the cut to the nose tip is empty");

  // d, second part: from the nose tip down to the upper lip; it ends where it first touches
  // the mouth boundary (not at a mouth corner).
  std::vector<char> earlier = flags_of(cm.mesh, c);
  for (auto v : d) earlier[v.idx()] = 1;
  std::vector<SurfacePoint> d2_points;
  if (edge_paths) {
    std::vector<char> blocked = boundary_flags();
    for (size_t i = 0; i < blocked.size(); ++i) blocked[i] |= earlier[i];
    GVKIT_ASSIGN_OR_RETURN(d2_points,
                           shortest_edge_path(cm.mesh, nose, lip, blocked, {}, "d (to the mouth)"));
  } else {
    const std::vector<double> to_lip = cm.field(kToLip);
    std::vector<char> is_lip(cm.mesh.n_vertices(), 0);
    is_lip[lip.idx()] = 1;
    std::vector<char> is_mouth = loop_flags(cm.mesh, mouth_loop);
    is_mouth[key_vertex[60].idx()] = is_mouth[key_vertex[64].idx()] = 0;
    GVKIT_ASSIGN_OR_RETURN(
        d2_points, trace_cut(cm.mesh, to_lip, nose, is_lip, {}, is_mouth, options.path, false));
  }
  GVKIT_RETURN_IF_ERROR(
      check_path(cm.mesh, d2_points, earlier, edges_of(cm.mesh, {&c, &d}), "d (to the mouth)"));
  const std::vector<Mesh::VertexHandle> d2 = insert_path(cm, d2_points);
  if (d2.size() < 2) return failed_precondition("face annulus: the cut to the mouth is empty");
  d.insert(d.end(), d2.begin() + 1, d2.end());
  const Mesh::VertexHandle d_end = d.back();

  std::vector<char> cut(cm.mesh.n_edges(), 0);
  for (const auto* path : {&c, &d})
    for (size_t i = 1; i < path->size(); ++i) {
      const auto h = cm.mesh.find_halfedge((*path)[i - 1], (*path)[i]);
      GVKIT_CHECK(h.is_valid(), "consecutive path vertices share an edge");
      if (cm.mesh.is_boundary(cm.mesh.edge_handle(h)))
        return failed_precondition("face annulus: a cut runs along a boundary");
      cut[cm.mesh.edge_handle(h).idx()] = 1;
    }
  // An interior edge joining two vertices of the same boundary of the annulus would make
  // triangles whose corners all have the same t (zero area in (s, t)); split such edges.
  {
    std::vector<char> inner(cm.mesh.n_vertices(), 0), rim(cm.mesh.n_vertices(), 0);
    for (auto v : cm.mesh.vertices())
      if (cm.mesh.is_boundary(v)) inner[v.idx()] = 1;
    for (auto v : boundaries.loops[FaceBoundaries::kRim]) rim[v.idx()] = 1, inner[v.idx()] = 0;
    for (const auto* path : {&c, &d})
      for (auto v : *path) inner[v.idx()] = 1;
    const int n_edges = static_cast<int>(cm.mesh.n_edges());
    for (int e = 0; e < n_edges; ++e) {
      const auto eh = cm.mesh.edge_handle(e);
      if (cut[e] || cm.mesh.is_boundary(eh)) continue;
      const auto h = cm.mesh.halfedge_handle(eh, 0);
      const int a = cm.mesh.from_vertex_handle(h).idx(), b = cm.mesh.to_vertex_handle(h).idx();
      if ((inner[a] && inner[b]) || (rim[a] && rim[b])) split_edge_at(cm, h, 0.5);
    }
    cut.resize(cm.mesh.n_edges(), 0);
  }

  FaceAnnulus a;
  a.surface = cut_along_edges(cm, cut);
  auto loops = tri_surface_boundary_loops(a.surface);
  if (loops.size() != 2)
    return failed_precondition("face annulus: cutting along c and d left " +
                               std::to_string(loops.size()) + " boundary loops, need 2");
  const int rim_vertex = boundaries.loops[FaceBoundaries::kRim][0].idx();
  const bool first_is_outer = std::any_of(loops[0].begin(), loops[0].end(), [&](int v) {
    return a.surface.uncut_vertex[v] == rim_vertex;
  });
  a.outer_loop = loops[first_is_outer ? 0 : 1];
  a.inner_loop = loops[first_is_outer ? 1 : 0];
  // The rim anchor: where the line from the nose tip (30) through the chin (8) leaves the face
  // in the frontal (x, y) plane (the farthest crossing of the rim along the line).
  {
    const cv::Vec3f& q30 = landmarks.points_mm[30];
    const cv::Vec3f& q8 = landmarks.chin_or_lower_lip_mm();
    const Eigen::Vector2d o(q30[0], q30[1]);
    const Eigen::Vector2d dir = Eigen::Vector2d(q8[0] - q30[0], q8[1] - q30[1]).normalized();
    a.rim_centre = o;
    a.rim_direction = dir;
    const auto& loop = a.outer_loop;
    const int m = static_cast<int>(loop.size());
    double best_along = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < m; ++i) {
      const Eigen::Vector2d r0 = a.surface.xyz[loop[i]].head<2>() - o;
      const Eigen::Vector2d r1 = a.surface.xyz[loop[(i + 1) % m]].head<2>() - o;
      const double c0 = dir.x() * r0.y() - dir.y() * r0.x(),
                   c1 = dir.x() * r1.y() - dir.y() * r1.x();
      if ((c0 <= 0) == (c1 <= 0) || c0 == c1) continue;
      const double t = c0 / (c0 - c1);
      const double along = dir.dot(r0 + t * (r1 - r0));
      if (along > best_along)
        best_along = along, a.rim_anchor = {loop[i], loop[(i + 1) % m]}, a.rim_anchor_t = t;
    }
    if (a.rim_anchor[0] < 0)
      return failed_precondition(
          "face annulus: the line from the nose tip (30) through the chin (8) does not meet the "
          "rim");
  }

  auto& key_uncut = a.key_vertices_uncut;
  for (int lm : kBoundaryKeyLandmarks)
    key_uncut.emplace_back(std::to_string(lm), key_vertex[lm].idx());
  key_uncut.emplace_back(kCMid, mid.idx());
  key_uncut.emplace_back(kNose, nose.idx());
  key_uncut.emplace_back(kDEnd, d_end.idx());
  a.cut_method = edge_paths ? "edge_path" : "descent";
  GVKIT_RETURN_IF_ERROR(locate_keys(a, key_uncut));
  // Copies of each key: 36, 45, 60, 64 once; 39, 42, the nose tip and d's end twice (both sides
  // of a cut); c's middle three times. Fewer means a cut ran along a boundary or the other cut.
  std::map<std::string, int> copies;
  for (const auto& k : a.keys) ++copies[k.name.substr(0, k.name.find('#'))];
  const std::map<std::string, int> expected = {{"36", 1},  {"45", 1},  {"60", 1},
                                               {"64", 1},  {"39", 2},  {"42", 2},
                                               {kNose, 2}, {kDEnd, 2}, {kCMid, 3}};
  if (copies != expected)
    return failed_precondition(
        "face annulus: the cuts leave the key points in an unexpected "
        "arrangement on the inner boundary");
  return a;
}

}  // namespace

Result<FaceAnnulus> make_face_annulus(const Mesh& mesh, const FaceLandmarks& landmarks,
                                      const DistanceFunction& distance,
                                      const FaceAnnulusOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  Mesh work = mesh;
  std::vector<int> original;
  const int pinch_faces = open_boundary_pinches(&work, &original);
  GVKIT_ASSIGN_OR_RETURN(FaceBoundaries boundaries,
                         find_face_boundaries(work, landmarks, options.boundaries));
  double distance_ms = 0;
  const DistanceFunction timed_distance =
      [&](const Mesh& m, const std::vector<Mesh::VertexHandle>& sources, double edge_scale) {
        const double start = thread_cpu_ms();
        auto fields = distance(m, sources, edge_scale);
        distance_ms += thread_cpu_ms() - start;
        return fields;
      };
  auto attempt = [&](bool edge_paths, double crop_mm) {
    Result<FaceAnnulus> a = build_annulus(work, original, landmarks, boundaries, timed_distance,
                                          options, edge_paths, crop_mm);
    if (a.is_ok()) a->pinch_faces_removed = pinch_faces, a->distance_ms = distance_ms;
    return a;
  };
  if (!options.descent_paths) return attempt(true, 0);
  Result<FaceAnnulus> descent = attempt(false, options.distance_crop_mm);
  // A descent that failed on the cropped fields gets the whole mesh's before the edge paths.
  if (!descent.is_ok() && options.distance_crop_mm > 0) descent = attempt(false, 0);
  if (descent.is_ok() || !options.edge_path_fallback) return descent;
  Result<FaceAnnulus> edge = attempt(true, 0);
  if (edge.is_ok()) return edge;
  return failed_precondition(descent.status().message() +
                             "; as edge paths: " + edge.status().message());
}

}  // namespace gvkit::facemap
