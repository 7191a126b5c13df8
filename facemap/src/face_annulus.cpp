#include "gvkit/facemap/face_annulus.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

#include "gvkit/facemap/mesh_cutting.hpp"

namespace gvkit::facemap {
namespace {

const char* kCMid = "c_mid";
const char* kDEnd = "d_end";

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
  std::vector<std::pair<std::string, int>> key_uncut;
  for (size_t i = 0; i < key_vertices_uncut.size(); ++i) {
    const std::string name = i < kBoundaryKeyLandmarks.size()
                                 ? std::to_string(kBoundaryKeyLandmarks[i])
                                 : (i == kBoundaryKeyLandmarks.size() ? kCMid : kDEnd);
    for (int v : key_vertices_uncut[i]) key_uncut.emplace_back(name, v);
  }
  GVKIT_CHECK(locate_keys(*this, key_uncut).is_ok());
}

Result<FaceAnnulus> make_face_annulus(const Mesh& mesh, const FaceLandmarks& landmarks,
                                      const DistanceFunction& distance,
                                      const FaceAnnulusOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  GVKIT_ASSIGN_OR_RETURN(FaceBoundaries boundaries,
                         find_face_boundaries(mesh, landmarks, options.boundaries));
  CuttableMesh cm(mesh);

  // Key landmarks projected onto their loops, as vertices (splitting boundary edges).
  std::map<int, Mesh::VertexHandle> key_vertex;
  for (int lm : kBoundaryKeyLandmarks) {
    auto& loop = boundaries.loops[FaceBoundaries::loop_of_landmark(lm)];
    const cv::Vec3f& q = landmarks.points_mm[lm];
    const LoopPoint lp = closest_loop_point(cm.mesh, loop, Eigen::Vector3d(q[0], q[1], q[2]));
    const int n = static_cast<int>(loop.size());
    Mesh::VertexHandle v;
    if (lp.t <= options.key_snap_fraction) {
      v = loop[lp.edge];
    } else if (lp.t >= 1.0 - options.key_snap_fraction) {
      v = loop[(lp.edge + 1) % n];
    } else {
      const auto h = cm.mesh.find_halfedge(loop[lp.edge], loop[(lp.edge + 1) % n]);
      GVKIT_CHECK(h.is_valid() && cm.mesh.is_boundary(h));
      v = split_edge_at(cm, h, lp.t);
      loop.insert(loop.begin() + lp.edge + 1, v);
    }
    for (const auto& [other, ov] : key_vertex)
      if (ov == v)
        return failed_precondition("landmarks " + std::to_string(other) + " and " +
                                   std::to_string(lm) + " land on the same boundary point");
    key_vertex[lm] = v;
  }

  // c: from the left inner eye corner (42) down the distance from the right one (39).
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> to_39, distance(cm.mesh, {key_vertex[39]}));
  std::vector<char> is_39(cm.mesh.n_vertices(), 0);
  is_39[key_vertex[39].idx()] = 1;
  GVKIT_ASSIGN_OR_RETURN(std::vector<SurfacePoint> c_points,
                         trace_cut(cm.mesh, to_39, key_vertex[42], is_39,
                                   loop_flags(cm.mesh, boundaries.loops[FaceBoundaries::kEyeLeft]),
                                   loop_flags(cm.mesh, boundaries.loops[FaceBoundaries::kEyeRight]),
                                   options.path, options.slide_along_start));
  std::vector<Mesh::VertexHandle> c = insert_path(cm, c_points);
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
  Mesh::VertexHandle mid;
  if (t < 0.25 && seg > 0) {
    mid = c[seg];
  } else if (t > 0.75 && seg + 2 < c.size()) {
    mid = c[seg + 1];
  } else {
    const auto h = cm.mesh.find_halfedge(c[seg], c[seg + 1]);
    GVKIT_CHECK(h.is_valid(), "consecutive path vertices share an edge");
    mid = split_edge_at(cm, h, t);
    c.insert(c.begin() + static_cast<std::ptrdiff_t>(seg) + 1, mid);
  }

  // d: from the middle of c down the distance from the upper lip's middle (landmark 62 projected
  // onto the mouth boundary). Where d first touches the mouth boundary is d's end.
  const std::vector<Mesh::VertexHandle>& mouth_loop = boundaries.loops[FaceBoundaries::kMouth];
  Mesh::VertexHandle lip;
  {
    const cv::Vec3f& q = landmarks.points_mm[62];
    const LoopPoint lp = closest_loop_point(cm.mesh, mouth_loop, Eigen::Vector3d(q[0], q[1], q[2]));
    lip = mouth_loop[lp.t < 0.5 ? lp.edge : (lp.edge + 1) % mouth_loop.size()];
    if (lip == key_vertex[60] || lip == key_vertex[64])
      return failed_precondition("landmark 62 lands on a mouth corner of the mouth boundary");
  }
  GVKIT_ASSIGN_OR_RETURN(std::vector<double> to_lip, distance(cm.mesh, {lip}));
  std::vector<char> is_lip(cm.mesh.n_vertices(), 0);
  is_lip[lip.idx()] = 1;
  std::vector<char> is_mouth = loop_flags(cm.mesh, mouth_loop);
  is_mouth[key_vertex[60].idx()] = is_mouth[key_vertex[64].idx()] = 0;
  GVKIT_ASSIGN_OR_RETURN(
      std::vector<SurfacePoint> d_points,
      trace_cut(cm.mesh, to_lip, mid, is_lip, {}, is_mouth, options.path, false));
  std::vector<Mesh::VertexHandle> d = insert_path(cm, d_points);
  const Mesh::VertexHandle d_end = d.back();
  const std::set<Mesh::VertexHandle> c_set(c.begin(), c.end());
  for (size_t i = 1; i < d.size(); ++i)
    if (c_set.count(d[i]))
      return failed_precondition(
          "face annulus: the cut d from the middle of c to the mouth "
          "runs back into c");

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

  std::vector<std::pair<std::string, int>> key_uncut;
  a.key_vertices_uncut.resize(kBoundaryKeyLandmarks.size() + 2);
  for (size_t i = 0; i < kBoundaryKeyLandmarks.size(); ++i) {
    const int v = key_vertex[kBoundaryKeyLandmarks[i]].idx();
    a.key_vertices_uncut[i] = {v};
    key_uncut.emplace_back(std::to_string(kBoundaryKeyLandmarks[i]), v);
  }
  a.key_vertices_uncut[kBoundaryKeyLandmarks.size()] = {mid.idx()};
  a.key_vertices_uncut[kBoundaryKeyLandmarks.size() + 1] = {d_end.idx()};
  key_uncut.emplace_back(kCMid, mid.idx());
  key_uncut.emplace_back(kDEnd, d_end.idx());
  GVKIT_RETURN_IF_ERROR(locate_keys(a, key_uncut));
  return a;
}

}  // namespace gvkit::facemap
