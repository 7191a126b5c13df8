#include "gvkit/player/manifold_verdict_cache.hpp"

namespace gvkit::player {

bool ManifoldVerdictCache::manifold(const MeshBuffers& buffers,
                                    const GeometryImageMeshOptions& options) {
  // With long edges dropped, the diagonal decides which triangles are left: no reuse.
  const bool reusable = options.max_edge_mm == 0;
  if (reusable) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (valid_ && width_ == buffers.width && height_ == buffers.height &&
        stride_ == options.stride && partial_quads_ == options.partial_quads &&
        pixels_ == buffers.pixel_index)
      return verdict_;
  }
  const bool verdict = mesh_buffers_manifold(buffers);
  std::lock_guard<std::mutex> lock(mutex_);
  ++checks_;
  if (reusable) {
    valid_ = true;
    verdict_ = verdict;
    width_ = buffers.width;
    height_ = buffers.height;
    stride_ = options.stride;
    partial_quads_ = options.partial_quads;
    pixels_ = buffers.pixel_index;
  }
  return verdict;
}

int ManifoldVerdictCache::checks() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return checks_;
}

}  // namespace gvkit::player
