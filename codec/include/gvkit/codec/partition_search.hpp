#pragma once
// Format 1.7 (inter partitions, docs/bitstream.md 4.11): the motion refinement of one partition
// of a P macroblock (a w x h block, w and h 8 or 16) against an interpolated reference. It starts
// from the best of a few given vectors (the 16x16 search result, the partition's predictor),
// takes whole-sample diamond steps while they lower the cost, then (with sub-sample motion) the
// eight half-sample and then quarter-sample neighbours of the best vector. Cost: SATD (SAD when
// lossless) of the 8x8 blocks of the partition + lambda * the Exp-Golomb bits of the vector
// difference to the predictor. Vectors in the stream's units (quarter samples when subpel != 0).

#include <cstdint>
#include <span>
#include <vector>

#include "gvkit/codec/motion_compensation.hpp"
#include "gvkit/codec/plane_coding.hpp"

namespace gvkit::codec {

struct PartitionSearchParams {
  int subpel = 0;         // 0 (whole samples), 2 (refine to half) or 4 (to quarter samples)
  bool lossless = false;  // SAD instead of SATD
  double lambda = 1;      // cost of one motion bit in distortion units
  int max_abs_mv = 256;   // limit on |vector component| (vector units)
  int max_steps = 8;      // whole-sample diamond steps at most
};

struct PartitionVector {
  int mv_x = 0, mv_y = 0;
  double cost = 0;  // distortion + lambda * bits of the chosen vector
};

// The distortions (SATD or SAD) of 8x8 blocks at vectors already measured, so that the searches
// of the partitions of one macroblock (16x8, 8x16 and 8x8 all cover the same four 8x8 blocks,
// from similar starts) measure each block at each vector once. Keyed by the block's position,
// the reference (an opaque id the caller gives) and the vector; clear() between macroblocks or
// whenever the source or a reference changes. A fixed-size table: when it is full, values are
// measured again (the results never depend on it).
class BlockDistortionMemo {
 public:
  BlockDistortionMemo();
  void clear() { ++generation_; }
  // The stored distortion, or -1 when none is.
  int64_t find(int ref, int x0, int y0, int mx, int my) const;
  void store(int ref, int x0, int y0, int mx, int my, int64_t distortion);

 private:
  struct Slot {
    uint64_t key = 0;
    uint32_t generation = 0;
    int64_t value = 0;
  };
  static uint64_t key_of(int ref, int x0, int y0, int mx, int my);
  static constexpr size_t kSlots = 1024;  // a power of two
  std::vector<Slot> slots_;
  uint32_t generation_ = 1;
};

// The w x h block at (x0, y0) of src (w, h in {8, 16}; inside src, the size of the reference);
// (px, py) is the partition's vector predictor; starts holds at least one vector (x, y pairs).
// With a memo (and ref_id naming `ref` in it), 8x8 distortions measured before are reused.
PartitionVector search_partition_motion(const SamplePlane& src, const InterpolatedReference& ref,
                                        int x0, int y0, int w, int h, int px, int py,
                                        std::span<const int> starts,
                                        const PartitionSearchParams& params,
                                        BlockDistortionMemo* memo = nullptr, int ref_id = 0);

}  // namespace gvkit::codec
