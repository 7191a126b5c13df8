#include "gvkit/facemap/triangle_soup_repair.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace gvkit::facemap {
namespace {

// One side of an undirected edge: the triangle, and whether it runs from the smaller corner index
// to the larger.
struct EdgeSide {
  uint64_t key;
  int triangle;
  bool ascending;
  bool operator<(const EdgeSide& o) const {
    return key != o.key ? key < o.key : triangle < o.triangle;
  }
};

// The edge sides of every triangle not dropped, sorted by edge (then triangle).
std::vector<EdgeSide> edge_sides(const std::vector<std::array<int, 3>>& triangles,
                                 const std::vector<char>& drop) {
  std::vector<EdgeSide> sides;
  sides.reserve(3 * triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    if (drop[t]) continue;
    for (int k = 0; k < 3; ++k) {
      const int a = triangles[t][k], b = triangles[t][(k + 1) % 3];
      const auto lo = static_cast<uint64_t>(std::min(a, b)),
                 hi = static_cast<uint64_t>(std::max(a, b));
      sides.push_back({(lo << 32) | hi, static_cast<int>(t), a < b});
    }
  }
  std::sort(sides.begin(), sides.end());
  return sides;
}

// Calls f(first, last) for each run of sides on the same edge.
template <typename F>
void for_each_edge(const std::vector<EdgeSide>& sides, F&& f) {
  for (size_t i = 0; i < sides.size();) {
    size_t j = i + 1;
    while (j < sides.size() && sides[j].key == sides[i].key) ++j;
    f(i, j);
    i = j;
  }
}

}  // namespace

int drop_non_finite_triangles(const std::vector<Mesh::Point>& points,
                              const std::vector<std::array<int, 3>>& triangles,
                              std::vector<char>* drop) {
  std::vector<char> finite(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    finite[i] =
        std::isfinite(points[i][0]) && std::isfinite(points[i][1]) && std::isfinite(points[i][2]);
  int dropped = 0;
  for (size_t t = 0; t < triangles.size(); ++t) {
    if ((*drop)[t]) continue;
    const auto& c = triangles[t];
    if (!finite[c[0]] || !finite[c[1]] || !finite[c[2]]) {
      (*drop)[t] = 1;
      ++dropped;
    }
  }
  return dropped;
}

FinReport drop_non_manifold_fins(const std::vector<std::array<int, 3>>& triangles,
                                 std::vector<char>* drop) {
  FinReport report;
  const std::vector<EdgeSide> sides = edge_sides(triangles, *drop);
  // Per triangle, how many of its edges it shares with exactly one other triangle.
  std::vector<int> embedded(triangles.size(), 0);
  bool any = false;
  for_each_edge(sides, [&](size_t i, size_t j) {
    if (j - i == 2) {
      ++embedded[sides[i].triangle];
      ++embedded[sides[i + 1].triangle];
    }
    any |= j - i > 2;
  });
  if (!any) return report;
  std::vector<char> doomed(triangles.size(), 0);
  for_each_edge(sides, [&](size_t i, size_t j) {
    if (j - i <= 2) return;
    ++report.non_manifold_edges;
    // The pair to keep: most embedded, then crossing the edge in opposite directions, then the
    // lower triangle indices (sides are sorted by triangle).
    long best = -1;
    size_t keep_a = i, keep_b = i + 1;
    for (size_t a = i; a < j; ++a)
      for (size_t b = a + 1; b < j; ++b) {
        const long score = 4L * (embedded[sides[a].triangle] + embedded[sides[b].triangle]) +
                           (sides[a].ascending != sides[b].ascending ? 1 : 0);
        if (score > best) best = score, keep_a = a, keep_b = b;
      }
    for (size_t s = i; s < j; ++s)
      if (s != keep_a && s != keep_b) doomed[sides[s].triangle] = 1;
  });
  for (size_t t = 0; t < triangles.size(); ++t)
    if (doomed[t] && !(*drop)[t]) {
      (*drop)[t] = 1;
      ++report.dropped_faces;
    }
  return report;
}

int orient_triangles(std::vector<std::array<int, 3>>* triangles, const std::vector<char>& drop,
                     std::vector<char>* flipped) {
  const int n = static_cast<int>(triangles->size());
  const std::vector<EdgeSide> sides = edge_sides(*triangles, drop);
  // Neighbours across manifold edges (CSR), with whether the pair needs opposite parities.
  std::vector<int> start(static_cast<size_t>(n) + 1, 0);
  for_each_edge(sides, [&](size_t i, size_t j) {
    if (j - i != 2) return;
    ++start[sides[i].triangle + 1];
    ++start[sides[i + 1].triangle + 1];
  });
  for (int t = 0; t < n; ++t) start[t + 1] += start[t];
  std::vector<int> neighbour(start[n]);
  std::vector<char> differ(start[n]);
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for_each_edge(sides, [&](size_t i, size_t j) {
      if (j - i != 2) return;
      const int a = sides[i].triangle, b = sides[i + 1].triangle;
      // Consistent neighbours run along the shared edge in opposite directions.
      const char d = sides[i].ascending == sides[i + 1].ascending ? 1 : 0;
      neighbour[fill[a]] = b;
      differ[fill[a]++] = d;
      neighbour[fill[b]] = a;
      differ[fill[b]++] = d;
    });
  }
  std::vector<signed char> parity(n, -1);
  std::vector<int> piece, queue;
  int total = 0;
  if (flipped) flipped->assign(n, 0);
  for (int seed = 0; seed < n; ++seed) {
    if (drop[seed] || parity[seed] >= 0) continue;
    piece.clear();
    queue.assign(1, seed);
    parity[seed] = 0;
    int ones = 0;
    for (size_t q = 0; q < queue.size(); ++q) {
      const int t = queue[q];
      piece.push_back(t);
      ones += parity[t];
      for (int e = start[t]; e < start[t + 1]; ++e) {
        const int u = neighbour[e];
        if (parity[u] >= 0) continue;  // seen (a conflict in a non-orientable piece is left)
        parity[u] = static_cast<signed char>(parity[t] ^ differ[e]);
        queue.push_back(u);
      }
    }
    // The majority winding stays: the minority parity is flipped.
    const int minority = ones * 2 > static_cast<int>(piece.size()) ? 0 : 1;
    for (int t : piece) {
      if (parity[t] != minority) continue;
      std::swap((*triangles)[t][1], (*triangles)[t][2]);
      if (flipped) (*flipped)[t] = 1;
      ++total;
    }
  }
  return total;
}

}  // namespace gvkit::facemap
