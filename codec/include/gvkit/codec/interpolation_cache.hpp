#pragma once
// ReferenceInterpolationCache: an encoder's store of InterpolatedReference objects (a reference
// plane with its half-sample planes, motion_compensation.hpp), so that a reference plane used by
// several planes of a frame (joint motion search) or by several frames (an anchor is reference 0,
// then an older reference of the next P frames, and list 0 / list 1 of the B frames between) is
// interpolated once instead of once per use. Encoder only; the coded stream does not depend on it
// (an InterpolatedReference is a function of the plane's samples, bit depth and margin alone).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "gvkit/codec/motion_compensation.hpp"
#include "gvkit/codec/plane_coding.hpp"

namespace gvkit::codec {

class ReferenceInterpolationCache {
 public:
  // The interpolated planes of `ref` (8 <= bit_depth <= 16, margin >= 0, as InterpolatedReference):
  // the stored object when one was made for the same plane object (same address) with the same
  // size and samples, bit depth and margin, else one made now (and stored, replacing any other
  // of that address). The result reads `ref` (its fallback path): use it while ref lives.
  // Safe to call from several threads at once.
  std::shared_ptr<const InterpolatedReference> get(const SamplePlane& ref, int bit_depth,
                                                   int margin);

  // Ends a frame: drops the entries not asked for during the frame that just ended nor the one
  // before it (an anchor stays while the following frames keep predicting from it).
  void next_frame();

  // Entries held now; objects made (misses) and entries reused (hits) so far.
  size_t size() const;
  int64_t made() const;
  int64_t reused() const;

 private:
  struct Entry {
    const SamplePlane* key = nullptr;
    int width = 0, height = 0, bit_depth = 0, margin = 0;
    std::vector<uint16_t> samples;  // the samples it was made from (checked on every hit)
    std::shared_ptr<const InterpolatedReference> interpolated;
    uint64_t last_used = 0;  // frame generation of the last get
  };

  mutable std::mutex mutex_;
  std::vector<Entry> entries_;
  uint64_t generation_ = 0;
  int64_t made_ = 0, reused_ = 0;
};

}  // namespace gvkit::codec
