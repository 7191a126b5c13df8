#include "gvkit/codec/interpolation_cache.hpp"

#include <algorithm>
#include <utility>

namespace gvkit::codec {
namespace {

bool same_plane(const SamplePlane& ref, int bit_depth, int margin, const SamplePlane* key,
                int width, int height, int entry_bit_depth, int entry_margin,
                const std::vector<uint16_t>& samples) {
  return key == &ref && width == ref.width && height == ref.height &&
         entry_bit_depth == bit_depth && entry_margin == margin && samples == ref.samples;
}

}  // namespace

std::shared_ptr<const InterpolatedReference> ReferenceInterpolationCache::get(
    const SamplePlane& ref, int bit_depth, int margin) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (Entry& e : entries_)
      if (same_plane(ref, bit_depth, margin, e.key, e.width, e.height, e.bit_depth, e.margin,
                     e.samples)) {
        e.last_used = generation_;
        ++reused_;
        return e.interpolated;
      }
  }
  // Made outside the lock (planes coded in parallel interpolate their references at once).
  auto made = std::make_shared<const InterpolatedReference>(ref, bit_depth, margin);
  const std::lock_guard<std::mutex> lock(mutex_);
  ++made_;
  // Another thread may have stored the same plane meanwhile: either object is as good.
  entries_.erase(std::remove_if(entries_.begin(), entries_.end(),
                                [&](const Entry& e) { return e.key == &ref; }),
                 entries_.end());
  Entry e;
  e.key = &ref;
  e.width = ref.width;
  e.height = ref.height;
  e.bit_depth = bit_depth;
  e.margin = margin;
  e.samples = ref.samples;
  e.interpolated = made;
  e.last_used = generation_;
  entries_.push_back(std::move(e));
  return made;
}

void ReferenceInterpolationCache::next_frame() {
  const std::lock_guard<std::mutex> lock(mutex_);
  ++generation_;
  entries_.erase(std::remove_if(entries_.begin(), entries_.end(),
                                [&](const Entry& e) { return e.last_used + 2 < generation_; }),
                 entries_.end());
}

size_t ReferenceInterpolationCache::size() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return entries_.size();
}

int64_t ReferenceInterpolationCache::made() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return made_;
}

int64_t ReferenceInterpolationCache::reused() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return reused_;
}

}  // namespace gvkit::codec
