#include "gvkit/facemap/shortest_edge_path.hpp"

#include <algorithm>
#include <functional>
#include <limits>
#include <queue>
#include <unordered_map>
#include <utility>

#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

ShortestEdgePaths::ShortestEdgePaths(const Mesh& mesh)
    : mesh_(&mesh),
      distance_(mesh.n_vertices(), std::numeric_limits<double>::infinity()),
      previous_(mesh.n_vertices(), -1) {}

std::vector<Mesh::VertexHandle> ShortestEdgePaths::path(Mesh::VertexHandle a,
                                                        Mesh::VertexHandle b) {
  const Mesh& mesh = *mesh_;
  const int n = static_cast<int>(distance_.size());
  GVKIT_CHECK(a.is_valid() && a.idx() < n && b.is_valid() && b.idx() < n,
              "shortest edge path: vertex out of range");
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  auto reach = [&](int i, double d, int from) {
    if (distance_[i] == std::numeric_limits<double>::infinity()) touched_.push_back(i);
    distance_[i] = d;
    previous_[i] = from;
  };
  reach(a.idx(), 0.0, -1);
  queue.emplace(0.0, a.idx());
  while (!queue.empty()) {
    const auto [d, i] = queue.top();
    queue.pop();
    if (d > distance_[i]) continue;
    if (i == b.idx()) break;
    for (auto h : mesh.voh_range(mesh.vertex_handle(i))) {
      const int j = mesh.to_vertex_handle(h).idx();
      const double nd = d + mesh.calc_edge_length(h);
      if (nd < distance_[j]) {
        reach(j, nd, i);
        queue.emplace(nd, j);
      }
    }
  }
  std::vector<Mesh::VertexHandle> out;
  if (distance_[b.idx()] < std::numeric_limits<double>::infinity()) {
    for (int i = b.idx(); i >= 0; i = previous_[i]) out.push_back(mesh.vertex_handle(i));
    std::reverse(out.begin(), out.end());
  }
  for (int i : touched_) {
    distance_[i] = std::numeric_limits<double>::infinity();
    previous_[i] = -1;
  }
  touched_.clear();
  return out;
}

std::vector<Mesh::VertexHandle> shortest_edge_path_reference(const Mesh& mesh, Mesh::VertexHandle a,
                                                             Mesh::VertexHandle b) {
  std::unordered_map<int, std::pair<double, int>> best;  // vertex -> (distance, previous)
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  best[a.idx()] = {0.0, -1};
  queue.emplace(0.0, a.idx());
  while (!queue.empty()) {
    const auto [d, i] = queue.top();
    queue.pop();
    if (d > best[i].first) continue;
    if (i == b.idx()) break;
    const auto v = mesh.vertex_handle(i);
    for (auto h : mesh.voh_range(v)) {
      const int j = mesh.to_vertex_handle(h).idx();
      const double nd = d + mesh.calc_edge_length(h);
      auto it = best.find(j);
      if (it == best.end() || nd < it->second.first) {
        best[j] = {nd, i};
        queue.emplace(nd, j);
      }
    }
  }
  std::vector<Mesh::VertexHandle> path;
  if (!best.count(b.idx())) return path;
  for (int i = b.idx(); i >= 0; i = best[i].second) path.push_back(mesh.vertex_handle(i));
  std::reverse(path.begin(), path.end());
  return path;
}

}  // namespace gvkit::facemap
