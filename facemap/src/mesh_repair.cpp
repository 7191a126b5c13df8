#include "gvkit/facemap/mesh_repair.hpp"

#include <algorithm>
#include <cstdint>
#include <mutex>
#include <numeric>
#include <set>

#include "gvkit/core/status.hpp"
#include "gvkit/facemap/triangle_soup_repair.hpp"

namespace gvkit::facemap {

bool MeshRepairReport::changed() const {
  return pinch_faces + non_finite_faces + degenerate_faces + duplicate_faces + non_manifold_faces +
             flipped_faces + removed_component_faces + removed_vertices >
         0;
}

std::string MeshRepairReport::summary() const {
  std::string s;
  auto add = [&](int n, const char* what) {
    if (n == 0) return;
    if (!s.empty()) s += ", ";
    s += std::to_string(n) + " " + what;
  };
  add(pinch_faces, "faces removed to open boundary pinches");
  add(non_finite_faces, "faces on non-finite points removed");
  add(degenerate_faces, "degenerate faces removed");
  add(duplicate_faces, "duplicate faces removed");
  add(non_manifold_faces, non_manifold_edges > 0 ? ("non-manifold faces removed (" +
                                                    std::to_string(non_manifold_edges) +
                                                    " edges with more than two faces)")
                                                       .c_str()
                                                 : "non-manifold faces removed");
  add(flipped_faces, "faces flipped to the winding of their neighbours");
  if (components > 1)
    add(removed_component_faces,
        ("faces in smaller components removed (" + std::to_string(components) + " components)")
            .c_str());
  add(removed_vertices, "unreferenced vertices removed");
  return s.empty() ? "no repair needed" : s;
}

namespace {

// Path halving (i moves to its grandparent, which becomes its parent), without the store when
// the grandparent is already i's parent: the root's entry, read by every find, is not rewritten.
int find_root(std::vector<int>& parent, int i) {
  for (int p = parent[i]; p != i; p = parent[i]) {
    const int g = parent[p];
    if (g == p) return p;
    parent[i] = g;
    i = g;
  }
  return i;
}

}  // namespace

bool build_half_edges(int n_vertices, const std::vector<std::array<int, 3>>& faces, Mesh* mesh) {
  const int nf = static_cast<int>(faces.size());
  const int nc = 3 * nf;  // face halfedge c = 3 t + k runs from faces[t][k] to faces[t][k + 1]
  const int* corner = faces.empty() ? nullptr : faces.front().data();
  auto next = [](int c) { return c % 3 == 2 ? c - 2 : c + 1; };
  auto prev = [](int c) { return c % 3 == 0 ? c + 2 : c - 1; };
  auto from = [&](int c) { return corner[c]; };
  auto to = [&](int c) { return corner[next(c)]; };
  // Face halfedges leaving each vertex (CSR).
  std::vector<int> out_start(static_cast<size_t>(n_vertices) + 1, 0);
  for (int c = 0; c < nc; ++c) {
    GVKIT_CHECK(corner[c] >= 0 && corner[c] < n_vertices, "triangle index out of range");
    ++out_start[corner[c] + 1];
  }
  for (int i = 0; i < n_vertices; ++i) out_start[i + 1] += out_start[i];
  std::vector<int> out(static_cast<size_t>(nc));
  {
    std::vector<int> fill(out_start.begin(), out_start.end() - 1);
    for (int c = 0; c < nc; ++c) out[fill[corner[c]]++] = c;
  }
  // Twins, per vertex a: its outgoing halfedges a -> b by b, then the incoming ones x -> a (the
  // previous halfedge of each outgoing one) look up a -> x. A directed edge used twice, a
  // degenerate face or a face equal to its three neighbours is not representable here.
  std::vector<int> twin(static_cast<size_t>(nc), -1);
  std::vector<int> stamp(n_vertices, -1), leaving(n_vertices, -1);
  for (int a = 0; a < n_vertices; ++a) {
    for (int i = out_start[a]; i < out_start[a + 1]; ++i) {
      const int c = out[i], b = to(c);
      if (b == a || stamp[b] == a) return false;
      stamp[b] = a;
      leaving[b] = c;
    }
    for (int i = out_start[a]; i < out_start[a + 1]; ++i) {
      const int d = prev(out[i]), x = from(d);  // d: x -> a
      if (stamp[x] == a) twin[d] = leaving[x];
    }
  }
  // One pass over the faces (the twins are complete) checks them, numbers the halfedges and finds
  // the open fans; a failed check ends the build, whichever pass would have found it.
  // OpenMesh halfedge ids: edge e holds 2e and 2e + 1; a boundary halfedge is the odd one.
  // Boundary: around each vertex, every open fan of faces has a boundary halfedge entering it
  // (the twin of its first face halfedge a -> b) and one leaving it on its other side. As in
  // OpenMesh, the entering halfedge of one fan continues with the leaving halfedge of the next
  // fan (in a cycle), so circulating around a vertex visits all its fans.
  std::vector<int> hedge(static_cast<size_t>(nc), -1);
  int n_edges = 0;
  std::vector<int> fan_faces(n_vertices, 0);
  std::vector<int> fans_start(static_cast<size_t>(n_vertices) + 1, 0);
  std::vector<int> fan_in, fan_out;  // per fan (grouped by vertex): entering c, leaving prev(c)
  std::vector<int> fan_vertex;
  for (int t = 0; t < nf; ++t) {
    const int* tw = &twin[3 * t];
    if (tw[0] >= 0 && tw[1] >= 0 && tw[2] >= 0 && tw[0] / 3 == tw[1] / 3 && tw[0] / 3 == tw[2] / 3)
      return false;  // a face equal to its three neighbours
    for (int c = 3 * t; c < 3 * t + 3; ++c) {
      const int tc = twin[c];
      if (tc >= 0 && twin[tc] != c) return false;
      if (hedge[c] < 0) {
        hedge[c] = 2 * n_edges;
        if (tc >= 0) hedge[tc] = 2 * n_edges + 1;
        ++n_edges;
      }
      if (tc >= 0) continue;
      const int a = from(c);
      int cur = c, steps = 1;
      for (; twin[prev(cur)] >= 0; ++steps) {
        cur = twin[prev(cur)];
        if (steps > out_start[a + 1] - out_start[a]) return false;
      }
      fan_in.push_back(c);
      fan_out.push_back(prev(cur));  // its twin (a -> x) is the boundary halfedge leaving a
      fan_vertex.push_back(a);
      fan_faces[a] += steps;
      ++fans_start[a + 1];
    }
  }
  for (int i = 0; i < n_vertices; ++i) fans_start[i + 1] += fans_start[i];
  std::vector<int> fans(fan_in.size());
  {
    std::vector<int> fill(fans_start.begin(), fans_start.end() - 1);
    for (size_t k = 0; k < fan_in.size(); ++k) fans[fill[fan_vertex[k]]++] = static_cast<int>(k);
  }
  // Per fan (in the order of fan_in, i.e. of its boundary corner c), the face halfedge whose twin
  // follows the boundary halfedge entering the fan.
  std::vector<int> next_boundary(fan_in.size());
  for (int a = 0; a < n_vertices; ++a) {
    const int first = fans_start[a], count = fans_start[a + 1] - first;
    for (int i = 0; i < count; ++i)
      next_boundary[fans[first + i]] = fan_out[fans[first + (i + 1) % count]];
  }
  for (int a = 0; a < n_vertices; ++a) {
    const int degree = out_start[a + 1] - out_start[a];
    if (degree == 0) continue;
    if (fans_start[a + 1] == fans_start[a]) {
      // One closed fan must hold all the faces.
      const int start = out[out_start[a]];
      int cur = start, steps = 0;
      do {
        cur = twin[prev(cur)];
        ++steps;
      } while (cur >= 0 && cur != start && steps <= degree);
      if (cur != start || steps != degree) return false;
    } else if (fan_faces[a] != degree) {
      return false;  // a closed fan besides the open ones
    }
  }

  // Room for a few percent more elements first, so that filling holes afterwards (which adds
  // vertices, edges and faces one at a time) does not reallocate and copy every array.
  auto spare = [](int count) { return static_cast<size_t>(count) + count / 32 + 64; };
  mesh->reserve(spare(n_vertices), spare(n_edges), spare(nf));
  mesh->resize(n_vertices, n_edges, nf);
  using HH = Mesh::HalfedgeHandle;
  int boundary_corner = 0;  // the boundary corners c come in the order of fan_in
  for (int t = 0; t < nf; ++t) {
    const Mesh::FaceHandle f(t);
    const HH h[3] = {HH(hedge[3 * t]), HH(hedge[3 * t + 1]), HH(hedge[3 * t + 2])};
    for (int k = 0; k < 3; ++k) {
      const int c = 3 * t + k;
      mesh->set_vertex_handle(h[k], Mesh::VertexHandle(to(c)));
      mesh->set_face_handle(h[k], f);
      mesh->set_next_halfedge_handle(h[k], h[k == 2 ? 0 : k + 1]);
      if (twin[c] < 0) {
        const HH g(h[k].idx() + 1);  // b -> a
        mesh->set_vertex_handle(g, Mesh::VertexHandle(from(c)));
        mesh->set_face_handle(g, Mesh::FaceHandle());
        mesh->set_next_halfedge_handle(g, HH(hedge[next_boundary[boundary_corner++]] + 1));
      }
    }
    mesh->set_halfedge_handle(f, h[0]);
  }
  // Each vertex's halfedge, once per vertex: on the boundary the boundary halfedge leaving its
  // last fan (of the largest boundary corner), inside the halfedge of its last corner (the
  // largest c: out[] lists each vertex's corners in increasing order).
  for (int a = 0; a < n_vertices; ++a) {
    if (out_start[a + 1] == out_start[a]) continue;
    const int last_fan = fans_start[a + 1] - 1;
    const int leaving = last_fan >= fans_start[a] ? hedge[next_boundary[fans[last_fan]]] + 1
                                                  : hedge[out[out_start[a + 1] - 1]];
    mesh->set_halfedge_handle(Mesh::VertexHandle(a), HH(leaving));
  }
  return true;
}

Mesh mesh_from_triangles(const std::vector<Mesh::Point>& points,
                         const std::vector<Mesh::Color>& colors,
                         const std::vector<std::array<int, 3>>& triangles,
                         const MeshRepairOptions& options, MeshRepairReport* report,
                         std::vector<int>* original_index, std::vector<int>* original_face) {
  Mesh mesh;
  mesh_from_triangles(points, colors, triangles, options, &mesh, report, original_index,
                      original_face);
  return mesh;
}

void mesh_from_triangles(const std::vector<Mesh::Point>& points,
                         const std::vector<Mesh::Color>& colors,
                         const std::vector<std::array<int, 3>>& triangles,
                         const MeshRepairOptions& options, Mesh* out, MeshRepairReport* report,
                         std::vector<int>* original_index, std::vector<int>* original_face) {
  MeshRepairReport local;
  MeshRepairReport& r = report ? *report : local;
  r = {};
  const int n = static_cast<int>(points.size());

  // Faces on non-finite points, degenerate and duplicate faces.
  std::vector<char> drop(triangles.size(), 0);
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) GVKIT_CHECK(t[k] >= 0 && t[k] < n, "triangle index out of range");
  r.non_finite_faces = drop_non_finite_triangles(points, triangles, &drop);
  // Duplicates by sorting (corner set, position): the first of equal corner sets is kept. Corner
  // sets are packed into one 64-bit key when the indices fit in 21 bits.
  std::vector<std::array<int, 3>> sorted_corners;
  if (options.check_duplicates) sorted_corners.reserve(triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i) {
    const auto& t = triangles[i];
    if (options.check_duplicates) {
      std::array<int, 3> key = t;
      std::sort(key.begin(), key.end());
      sorted_corners.push_back(key);
    }
    if (drop[i]) continue;
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0] ||
        ((points[t[1]] - points[t[0]]) % (points[t[2]] - points[t[0]])).sqrnorm() == 0.0) {
      ++r.degenerate_faces;
      drop[i] = 1;
    }
  }
  if (!options.check_duplicates) {
    // The caller's triangles have none (a pixel grid, a clipped manifold mesh); the direct build
    // refuses them if that is wrong, and the faces are then checked after all (below).
  } else if (n < (1 << 21)) {
    std::vector<std::pair<uint64_t, int>> keys;
    keys.reserve(triangles.size());
    for (size_t i = 0; i < triangles.size(); ++i) {
      if (drop[i]) continue;
      const auto& k = sorted_corners[i];
      keys.emplace_back((static_cast<uint64_t>(k[0]) << 42) | (static_cast<uint64_t>(k[1]) << 21) |
                            static_cast<uint64_t>(k[2]),
                        static_cast<int>(i));
    }
    std::sort(keys.begin(), keys.end());
    for (size_t k = 1; k < keys.size(); ++k)
      if (keys[k].first == keys[k - 1].first) {
        drop[keys[k].second] = 1;
        ++r.duplicate_faces;
      }
  } else {
    std::vector<std::pair<std::array<int, 3>, int>> keys;
    keys.reserve(triangles.size());
    for (size_t i = 0; i < triangles.size(); ++i)
      if (!drop[i]) keys.emplace_back(sorted_corners[i], static_cast<int>(i));
    std::sort(keys.begin(), keys.end());
    for (size_t k = 1; k < keys.size(); ++k)
      if (keys[k].first == keys[k - 1].first) {
        drop[keys[k].second] = 1;
        ++r.duplicate_faces;
      }
  }
  sorted_corners.clear();
  sorted_corners.shrink_to_fit();
  if (options.resolve_non_manifold_edges) {
    const FinReport fins = drop_non_manifold_fins(triangles, &drop);
    r.non_manifold_edges = fins.non_manifold_edges;
    r.non_manifold_faces = fins.dropped_faces;
  }
  // The faces not dropped (the caller's triangles themselves when none is and none is flipped),
  // with their input indices.
  std::vector<std::array<int, 3>> remaining;
  std::vector<int> remaining_index;
  const bool any_dropped = std::find(drop.begin(), drop.end(), 1) != drop.end();
  const bool copied = any_dropped || options.orient_faces;
  if (copied) {
    remaining.reserve(triangles.size());
    remaining_index.reserve(triangles.size());
    for (size_t i = 0; i < triangles.size(); ++i)
      if (!drop[i]) {
        remaining.push_back(triangles[i]);
        remaining_index.push_back(static_cast<int>(i));
      }
  }
  if (options.orient_faces)
    r.flipped_faces = orient_triangles(&remaining, std::vector<char>(remaining.size(), 0));
  const std::vector<std::array<int, 3>>& faces = copied ? remaining : triangles;
  auto input_face = [&](size_t i) { return copied ? remaining_index[i] : static_cast<int>(i); };

  // Components (union-find over face corners), keep the largest by face count.
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  // The roots depend only on the order of the unions, not on how paths are shortened.
  for (const auto& t : faces) {
    const int a = find_root(parent, t[0]);
    for (int k = 1; k < 3; ++k)
      if (const int root = find_root(parent, t[k]); root != a) parent[root] = a;
  }
  // Every vertex points at its root from here on (the same roots: flattening keeps them).
  for (int i = 0; i < n; ++i) parent[i] = find_root(parent, i);
  std::vector<int> faces_per_root(n, 0);
  for (const auto& t : faces) ++faces_per_root[parent[t[0]]];
  r.components = static_cast<int>(
      std::count_if(faces_per_root.begin(), faces_per_root.end(), [](int c) { return c > 0; }));
  int keep_root = -1;
  if (options.keep_largest_component && r.components > 1) {
    keep_root = static_cast<int>(std::max_element(faces_per_root.begin(), faces_per_root.end()) -
                                 faces_per_root.begin());
    double kept_area = 0.0, total_area = 0.0;
    for (const auto& t : faces) {
      const double area = ((points[t[1]] - points[t[0]]) % (points[t[2]] - points[t[0]])).norm();
      total_area += area;
      if (parent[t[0]] == keep_root) kept_area += area;
    }
    r.kept_area_share = total_area > 0 ? kept_area / total_area : 0.0;
  }

  // Kept faces on compact vertex indices (in order of first use).
  std::vector<int> compact(n, -1);
  std::vector<int> original;
  original.reserve(n);
  std::vector<std::array<int, 3>> kept;
  std::vector<int> kept_face;
  kept.reserve(faces.size());
  if (original_face) kept_face.reserve(faces.size());
  for (size_t i = 0; i < faces.size(); ++i) {
    const auto& t = faces[i];
    if (keep_root >= 0 && parent[t[0]] != keep_root) {
      ++r.removed_component_faces;
      continue;
    }
    if (original_face) kept_face.push_back(input_face(i));
    std::array<int, 3> c;
    for (int k = 0; k < 3; ++k) {
      if (compact[t[k]] < 0) {
        compact[t[k]] = static_cast<int>(original.size());
        original.push_back(t[k]);
      }
      c[k] = compact[t[k]];
    }
    kept.push_back(c);
  }
  remaining.clear();
  remaining.shrink_to_fit();
  remaining_index.clear();
  remaining_index.shrink_to_fit();

  const bool with_colors = !colors.empty();
  GVKIT_CHECK(!with_colors || colors.size() == points.size(), "one colour per point");
  Mesh& mesh = *out;
  mesh.clear();
  if (with_colors) mesh.request_vertex_colors();
  const int n_kept = static_cast<int>(original.size());
  if (options.direct_build && build_half_edges(n_kept, kept, &mesh)) {
    for (int i = 0; i < n_kept; ++i) {
      const Mesh::VertexHandle v(i);
      mesh.set_point(v, points[original[i]]);
      if (with_colors) mesh.set_color(v, colors[original[i]]);
    }
  } else if (!options.check_duplicates) {
    MeshRepairOptions checked = options;
    checked.check_duplicates = true;
    mesh_from_triangles(points, colors, triangles, checked, out, report, original_index,
                        original_face);
    return;
  } else {
    // The reference: OpenMesh's add_face, which refuses faces that would make an edge
    // non-manifold or a vertex complex. It reports refused faces on its own stream; they are
    // counted here instead.
    static std::once_flag silence;
    std::call_once(silence, [] { omerr().disable(); });
    mesh.clear();
    mesh.reserve(n_kept, 3 * kept.size() / 2 + n_kept, kept.size());
    for (int i = 0; i < n_kept; ++i) {
      const auto v = mesh.add_vertex(points[original[i]]);
      if (with_colors) mesh.set_color(v, colors[original[i]]);
    }
    std::vector<int> added_face;
    for (size_t i = 0; i < kept.size(); ++i) {
      const auto& t = kept[i];
      if (!mesh.add_face(Mesh::VertexHandle(t[0]), Mesh::VertexHandle(t[1]),
                         Mesh::VertexHandle(t[2]))
               .is_valid())
        ++r.non_manifold_faces;
      else if (original_face)
        added_face.push_back(kept_face[i]);
    }
    if (original_face) kept_face = std::move(added_face);
    // Vertices whose only faces were refused.
    bool any_isolated = false;
    for (auto v : mesh.vertices())
      if (mesh.is_isolated(v)) {
        mesh.delete_vertex(v, false);
        any_isolated = true;
      }
    if (any_isolated) {
      // Track the original indices through garbage collection via a vertex property.
      OpenMesh::VPropHandleT<int> orig;
      mesh.add_property(orig);
      for (auto v : mesh.all_vertices()) mesh.property(orig, v) = original[v.idx()];
      mesh.garbage_collection();
      original.assign(mesh.n_vertices(), -1);
      for (auto v : mesh.vertices()) original[v.idx()] = mesh.property(orig, v);
      mesh.remove_property(orig);
    }
  }
  r.removed_vertices = n - static_cast<int>(mesh.n_vertices());
  if (original_index) *original_index = std::move(original);
  if (original_face) *original_face = std::move(kept_face);
}

namespace {

// The points, colours (empty without vertex colours) and triangles of mesh.
void mesh_soup(const Mesh& mesh, std::vector<Mesh::Point>* points, std::vector<Mesh::Color>* colors,
               std::vector<std::array<int, 3>>* triangles) {
  points->reserve(mesh.n_vertices());
  for (auto v : mesh.vertices()) points->push_back(mesh.point(v));
  if (mesh.has_vertex_colors())
    for (auto v : mesh.vertices()) colors->push_back(mesh.color(v));
  triangles->reserve(mesh.n_faces());
  for (auto f : mesh.faces()) {
    std::array<int, 3> t;
    int k = 0;
    for (auto v : mesh.fv_range(f)) {
      if (k < 3) t[k] = v.idx();
      ++k;
    }
    if (k == 3) triangles->push_back(t);
  }
}

}  // namespace

MeshRepairReport repair_mesh(Mesh* mesh, const MeshRepairOptions& options) {
  std::vector<Mesh::Point> points;
  std::vector<Mesh::Color> colors;
  std::vector<std::array<int, 3>> triangles;
  mesh_soup(*mesh, &points, &colors, &triangles);
  MeshRepairReport report;
  *mesh = mesh_from_triangles(points, colors, triangles, options, &report);
  return report;
}

int open_pinched_fans(const std::vector<Mesh::Point>& points,
                      std::vector<std::array<int, 3>>* triangles) {
  const int n = static_cast<int>(points.size());
  int removed = 0;
  std::vector<int> offset, target, face, open_fans, parent;
  for (int round = 0; round < 50; ++round) {
    const auto& tris = *triangles;
    const int m = static_cast<int>(tris.size());
    // Directed edges a -> b of every triangle, grouped by a (CSR): target b and the triangle.
    offset.assign(n + 1, 0);
    for (const auto& t : tris)
      for (int v : t) ++offset[v + 1];
    for (int v = 0; v < n; ++v) offset[v + 1] += offset[v];
    target.resize(offset[n]);
    face.resize(offset[n]);
    {
      std::vector<int> fill(offset.begin(), offset.end() - 1);
      for (int k = 0; k < m; ++k)
        for (int j = 0; j < 3; ++j) {
          const int a = tris[k][j], slot = fill[a]++;
          target[slot] = tris[k][(j + 1) % 3];
          face[slot] = k;
        }
    }
    // The triangle holding directed edge a -> b, or -1.
    auto edge_face = [&](int a, int b) {
      for (int i = offset[a]; i < offset[a + 1]; ++i)
        if (target[i] == b) return face[i];
      return -1;
    };
    // One boundary halfedge leaves a vertex per open fan: triangle edge a -> b without b -> a is
    // the boundary halfedge b -> a.
    open_fans.assign(n, 0);
    for (int a = 0; a < n; ++a)
      for (int i = offset[a]; i < offset[a + 1]; ++i)
        if (edge_face(target[i], a) < 0) ++open_fans[target[i]];
    std::vector<char> doomed(m, 0);
    int pinches = 0;
    for (int v = 0; v < n; ++v) {
      if (open_fans[v] < 2) continue;
      ++pinches;
      // Fans: the triangles around v (one outgoing edge each), joined across their edges at v.
      const int first = offset[v], count = offset[v + 1] - first;
      parent.resize(count);
      std::iota(parent.begin(), parent.end(), 0);
      for (int i = 0; i < count; ++i) {
        const int across = edge_face(target[first + i], v);  // the triangle with w -> v
        if (across < 0) continue;
        for (int j = 0; j < count; ++j)
          if (face[first + j] == across) parent[find_root(parent, i)] = find_root(parent, j);
      }
      std::vector<double> fan_area(count, 0.0);
      for (int i = 0; i < count; ++i) {
        const auto& t = tris[face[first + i]];
        fan_area[find_root(parent, i)] +=
            ((points[t[1]] - points[t[0]]) % (points[t[2]] - points[t[0]])).norm();
      }
      const int keep =
          static_cast<int>(std::max_element(fan_area.begin(), fan_area.end()) - fan_area.begin());
      for (int i = 0; i < count; ++i)
        if (find_root(parent, i) != keep) doomed[face[first + i]] = 1;
    }
    if (pinches == 0) break;
    std::vector<std::array<int, 3>> kept;
    kept.reserve(m);
    for (int k = 0; k < m; ++k)
      if (doomed[k])
        ++removed;
      else
        kept.push_back(tris[k]);
    *triangles = std::move(kept);
  }
  return removed;
}

int open_boundary_pinches(Mesh* mesh, std::vector<int>* original) {
  // Most meshes have no pinch: the mesh's own boundary halfedges tell, without a copy.
  std::vector<int> open_fans(mesh->n_vertices(), 0);
  bool pinched = false;
  for (auto h : mesh->halfedges())
    if (mesh->is_boundary(h)) pinched |= ++open_fans[mesh->from_vertex_handle(h).idx()] > 1;
  if (!pinched) {
    if (original) {
      original->resize(mesh->n_vertices());
      std::iota(original->begin(), original->end(), 0);
    }
    return 0;
  }
  std::vector<Mesh::Point> points;
  std::vector<Mesh::Color> colors;
  std::vector<std::array<int, 3>> triangles;
  mesh_soup(*mesh, &points, &colors, &triangles);
  const size_t before = triangles.size();
  open_pinched_fans(points, &triangles);
  MeshRepairOptions options;
  options.keep_largest_component = true;
  options.check_duplicates = false;
  MeshRepairReport report;
  mesh_from_triangles(points, colors, triangles, options, mesh, &report, original);
  return static_cast<int>(before - mesh->n_faces());
}

}  // namespace gvkit::facemap
