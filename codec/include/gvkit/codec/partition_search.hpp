#pragma once
// Format 1.7 (inter partitions, docs/bitstream.md 4.11): the motion refinement of one partition
// of a P macroblock (a w x h block, w and h 8 or 16) against an interpolated reference. It starts
// from the best of a few given vectors (the 16x16 search result, the partition's predictor),
// takes whole-sample diamond steps while they lower the cost, then (with sub-sample motion) the
// eight half-sample and then quarter-sample neighbours of the best vector. Cost: SATD (SAD when
// lossless) of the 8x8 blocks of the partition + lambda * the Exp-Golomb bits of the vector
// difference to the predictor. Vectors in the stream's units (quarter samples when subpel != 0).

#include <span>

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

// The w x h block at (x0, y0) of src (w, h in {8, 16}; inside src, the size of the reference);
// (px, py) is the partition's vector predictor; starts holds at least one vector (x, y pairs).
PartitionVector search_partition_motion(const SamplePlane& src, const InterpolatedReference& ref,
                                        int x0, int y0, int w, int h, int px, int py,
                                        std::span<const int> starts,
                                        const PartitionSearchParams& params);

}  // namespace gvkit::codec
