#pragma once
// The directed edges (a -> b) of an indexed triangle list with the corner each starts at, in plain
// arrays grouped by start vertex, so "which triangle has the edge a -> b" is a scan of a's few
// edges instead of a lookup in an ordered map of all edges (the map stage's hot loops).

#include <array>
#include <vector>

namespace gvkit::facemap {

class DirectedEdges {
 public:
  DirectedEdges(const std::vector<std::array<int, 3>>& triangles, int n_vertices)
      : offset_(n_vertices + 1, 0) {
    for (const auto& t : triangles)
      for (int j = 0; j < 3; ++j) ++offset_[t[j] + 1];
    for (int v = 0; v < n_vertices; ++v) offset_[v + 1] += offset_[v];
    to_.resize(offset_[n_vertices]);
    corner_.resize(offset_[n_vertices]);
    std::vector<int> fill(offset_.begin(), offset_.end() - 1);
    for (int k = 0; k < static_cast<int>(triangles.size()); ++k)
      for (int j = 0; j < 3; ++j) {
        const int a = triangles[k][j];
        to_[fill[a]] = triangles[k][(j + 1) % 3];
        corner_[fill[a]++] = 3 * k + j;
      }
  }

  // The corner 3k + j of the first triangle k whose corner j is a and next corner is b (the edge
  // a -> b in its winding), or -1 when no triangle has it.
  int corner(int a, int b) const {
    for (int i = offset_[a]; i < offset_[a + 1]; ++i)
      if (to_[i] == b) return corner_[i];
    return -1;
  }
  // The triangle with the edge a -> b, or -1.
  int triangle(int a, int b) const {
    const int c = corner(a, b);
    return c < 0 ? -1 : c / 3;
  }
  // How many triangles have the edge a -> b.
  int count(int a, int b) const {
    int n = 0;
    for (int i = offset_[a]; i < offset_[a + 1]; ++i) n += to_[i] == b;
    return n;
  }
  // The edges leaving a are i in [begin(a), end(a)); to(i) is the vertex edge i leads to.
  int begin(int a) const { return offset_[a]; }
  int end(int a) const { return offset_[a + 1]; }
  int to(int i) const { return to_[i]; }

 private:
  std::vector<int> offset_, to_, corner_;
};

}  // namespace gvkit::facemap
