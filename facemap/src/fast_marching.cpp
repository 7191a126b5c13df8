#include "gvkit/facemap/fast_marching.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <utility>

#include "gvkit/core/status.hpp"

namespace gvkit::facemap {
namespace {

using Point = Mesh::Point;

// Distance at c from the front through a (distance da) and b (distance db), unfolded into the
// plane of the triangle (a, b, c).
double triangle_update(const Point& a, double da, const Point& b, double db, const Point& c) {
  const double edge_a = da + (c - a).norm(), edge_b = db + (c - b).norm();
  const double fallback = std::min(edge_a, edge_b);
  const Point ab = b - a, ac = c - a;
  const double len = ab.norm();
  if (!(len > 0)) return fallback;
  // c in the plane: a at the origin, b at (len, 0), c at (cx, cy) with cy >= 0.
  const double cx = (ac | ab) / len;
  const double cy = (ab % ac).norm() / len;
  // The virtual source s at distance da from a and db from b, on the far side of ab from c.
  const double sx = (da * da - db * db + len * len) / (2.0 * len);
  const double sy2 = da * da - sx * sx;
  if (sy2 < 0) return fallback;
  const double sy = -std::sqrt(sy2);
  // The line from s to c must cross ab between a and b.
  const double t = (0.0 - sy) / (cy - sy);
  const double x = sx + (cx - sx) * t;
  if (x < 0 || x > len) return fallback;
  return std::min(fallback, std::hypot(cx - sx, cy - sy));
}

}  // namespace

FastMarching::FastMarching(const Mesh& mesh) : mesh_(&mesh) {
  const int n = static_cast<int>(mesh.n_vertices());
  points_.assign(mesh.points(), mesh.points() + n);
  // Corners read from each face's halfedges in one pass (the order of fv_range: the targets of
  // the face's halfedge and its two successors), then the fans in CSR layout.
  std::vector<int> corners;
  corners.reserve(3 * mesh.n_faces());
  for (auto f : mesh.faces()) {
    const auto h0 = mesh.halfedge_handle(f);
    const auto h1 = mesh.next_halfedge_handle(h0);
    const auto h2 = mesh.next_halfedge_handle(h1);
    corners.push_back(mesh.to_vertex_handle(h0).idx());
    corners.push_back(mesh.to_vertex_handle(h1).idx());
    corners.push_back(mesh.to_vertex_handle(h2).idx());
  }
  fan_start_.assign(n + 1, 0);
  for (int c : corners) ++fan_start_[c + 1];
  for (int i = 0; i < n; ++i) fan_start_[i + 1] += fan_start_[i];
  fan_.resize(2 * static_cast<size_t>(fan_start_[n]));
  std::vector<int> fill(fan_start_.begin(), fan_start_.end() - 1);
  for (size_t t = 0; t < corners.size(); t += 3) {
    const int* c = &corners[t];
    for (int j = 0; j < 3; ++j) {
      const int slot = fill[c[j]]++;
      fan_[2 * slot] = c[(j + 1) % 3];
      fan_[2 * slot + 1] = c[(j + 2) % 3];
    }
  }
}

std::vector<double> FastMarching::distance_reference(const std::vector<Mesh::VertexHandle>& sources,
                                                     double max_distance_mm) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const int n = static_cast<int>(points_.size());
  std::vector<double> d(n, kInf);
  std::vector<char> accepted(n, 0);
  // Binary min-heap of vertices by (d, index) with each vertex's heap slot, so a relaxation
  // moves the vertex up instead of adding a second entry.
  std::vector<int> heap, slot(n, -1);
  heap.reserve(1024);
  auto less = [&](int a, int b) { return d[a] < d[b] || (d[a] == d[b] && a < b); };
  auto place = [&](int i, int v) {
    heap[i] = v;
    slot[v] = i;
  };
  auto sift_up = [&](int i) {
    const int v = heap[i];
    while (i > 0) {
      const int parent = (i - 1) / 2;
      if (!less(v, heap[parent])) break;
      place(i, heap[parent]);
      i = parent;
    }
    place(i, v);
  };
  auto sift_down = [&](int i) {
    const int size = static_cast<int>(heap.size());
    const int v = heap[i];
    for (;;) {
      int child = 2 * i + 1;
      if (child >= size) break;
      if (child + 1 < size && less(heap[child + 1], heap[child])) ++child;
      if (!less(heap[child], v)) break;
      place(i, heap[child]);
      i = child;
    }
    place(i, v);
  };
  auto relax = [&](int target, double value) {
    if (!(value < d[target])) return;
    d[target] = value;
    if (slot[target] < 0) {
      heap.push_back(target);
      slot[target] = static_cast<int>(heap.size()) - 1;
    }
    sift_up(slot[target]);
  };
  for (auto v : sources) {
    GVKIT_CHECK(v.is_valid() && v.idx() < n, "fast marching: source vertex out of range");
    relax(v.idx(), 0.0);
  }
  while (!heap.empty()) {
    const int v = heap.front();
    const double dv = d[v];
    if (dv > max_distance_mm) break;
    slot[v] = -1;
    const int last = heap.back();
    heap.pop_back();
    if (!heap.empty()) {
      place(0, last);
      sift_down(0);
    }
    accepted[v] = 1;
    const Point& pv = points_[v];
    for (int k = fan_start_[v]; k < fan_start_[v + 1]; ++k) {
      const int b = fan_[2 * k], c = fan_[2 * k + 1];
      if (!accepted[c]) {
        relax(c, accepted[b] ? triangle_update(pv, dv, points_[b], d[b], points_[c])
                             : dv + (points_[c] - pv).norm());
      }
      if (!accepted[b]) {
        relax(b, accepted[c] ? triangle_update(pv, dv, points_[c], d[c], points_[b])
                             : dv + (points_[b] - pv).norm());
      }
    }
  }
  for (int i = 0; i < n; ++i)
    if (!accepted[i]) d[i] = kInf;
  return d;
}

// The same computation as distance_reference, arranged for memory traffic:
// - the heap entries carry their key, so comparisons read the heap's own contiguous entries
//   instead of d[] at scattered vertex indices;
// - the heap is 4-ary: half the levels of a binary heap, so half the scattered slot[] writes per
//   sift, and the four children of an entry share a cache line;
// - one state array (heap slot, or kAccepted) instead of a slot and an accepted flag;
// - the fan and position of the vertex on top of the heap (most often the next one accepted)
//   are prefetched while the current vertex's triangles are updated.
// The order (d, index) is a strict total order, so whatever the heap's shape its top is the same
// vertex: vertices are accepted in the same order as in the reference, and every update reads
// the same accepted neighbours, so the values are the same to the last bit. Within one vertex the
// order of its triangles does not matter either: a vertex keeps the minimum of its updates.
namespace {
constexpr int kAccepted = -2;
}  // namespace

std::vector<double> FastMarching::distance(const std::vector<Mesh::VertexHandle>& sources,
                                           double max_distance_mm) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const int n = static_cast<int>(points_.size());
  std::vector<double> d(n, kInf);
  std::vector<int> state(n, -1);  // heap slot, -1 (not reached) or kAccepted
  march(sources, max_distance_mm, d.data(), state.data(), nullptr);
  for (int i = 0; i < n; ++i)
    if (state[i] != kAccepted) d[i] = kInf;
  return d;
}

std::vector<std::pair<int, double>> FastMarching::reached(
    const std::vector<Mesh::VertexHandle>& sources, double max_distance_mm) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const size_t n = points_.size();
  if (reached_d_.size() != n) {
    reached_d_.assign(n, kInf);
    reached_state_.assign(n, -1);
  }
  std::vector<int> touched;
  march(sources, max_distance_mm, reached_d_.data(), reached_state_.data(), &touched);
  std::vector<std::pair<int, double>> out;
  out.reserve(touched.size());
  for (int v : touched) {
    if (reached_state_[v] == kAccepted) out.emplace_back(v, reached_d_[v]);
    reached_d_[v] = kInf;
    reached_state_[v] = -1;
  }
  return out;
}

void FastMarching::march(const std::vector<Mesh::VertexHandle>& sources, double max_distance_mm,
                         double* d, int* state, std::vector<int>* touched) const {
  constexpr int kArity = 4;
  const int n = static_cast<int>(points_.size());
  struct Entry {
    double d;
    int v;
  };
  std::vector<Entry> heap;
  heap.reserve(1024);
  auto less = [](const Entry& a, const Entry& b) { return a.d < b.d || (a.d == b.d && a.v < b.v); };
  auto sift_up = [&](int i) {
    const Entry e = heap[i];
    while (i > 0) {
      const int parent = (i - 1) / kArity;
      if (!less(e, heap[parent])) break;
      heap[i] = heap[parent];
      state[heap[i].v] = i;
      i = parent;
    }
    heap[i] = e;
    state[e.v] = i;
  };
  auto sift_down = [&](int i) {
    const int size = static_cast<int>(heap.size());
    const Entry e = heap[i];
    for (;;) {
      const int first = kArity * i + 1;
      if (first >= size) break;
      int child = first;
      const int last = std::min(first + kArity, size);
      for (int k = first + 1; k < last; ++k)
        if (less(heap[k], heap[child])) child = k;
      if (!less(heap[child], e)) break;
      heap[i] = heap[child];
      state[heap[i].v] = i;
      i = child;
    }
    heap[i] = e;
    state[e.v] = i;
  };
  auto relax = [&](int target, double value) {
    if (!(value < d[target])) return;
    d[target] = value;
    if (state[target] < 0) {
      if (touched) touched->push_back(target);
      heap.push_back({value, target});
      sift_up(static_cast<int>(heap.size()) - 1);
    } else {
      heap[state[target]].d = value;
      sift_up(state[target]);
    }
  };
  for (auto v : sources) {
    GVKIT_CHECK(v.is_valid() && v.idx() < n, "fast marching: source vertex out of range");
    relax(v.idx(), 0.0);
  }
  const int* fan = fan_.data();
  const int* fan_start = fan_start_.data();
  const Point* points = points_.data();
  while (!heap.empty()) {
    const int v = heap.front().v;
    const double dv = d[v];
    if (dv > max_distance_mm) break;
    const Entry last = heap.back();
    heap.pop_back();
    if (!heap.empty()) {
      heap[0] = last;
      sift_down(0);
      const int next = heap[0].v;
      __builtin_prefetch(fan + 2 * fan_start[next]);
      __builtin_prefetch(points + next);
    }
    state[v] = kAccepted;
    const Point& pv = points[v];
    for (int k = fan_start[v]; k < fan_start[v + 1]; ++k) {
      const int b = fan[2 * k], c = fan[2 * k + 1];
      const bool b_accepted = state[b] == kAccepted, c_accepted = state[c] == kAccepted;
      if (!c_accepted)
        relax(c, b_accepted ? triangle_update(pv, dv, points[b], d[b], points[c])
                            : dv + (points[c] - pv).norm());
      if (!b_accepted)
        relax(b, c_accepted ? triangle_update(pv, dv, points[c], d[c], points[b])
                            : dv + (points[b] - pv).norm());
    }
  }
}

}  // namespace gvkit::facemap
