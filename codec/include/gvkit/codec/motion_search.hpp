#pragma once
// Motion estimation of one 16x16 macroblock of a P plane against an interpolated reference: an
// integer search by SAD + lambda * motion bits, then (with sub-sample motion) a refinement by SATD
// (SAD when lossless) + lambda * motion bits over the predictor and the half-sample, then
// quarter-sample, neighbours of the best vector. Vectors are in the stream's units: quarter
// samples when subpel != 0, else whole samples.

#include <span>

#include "gvkit/codec/motion_compensation.hpp"
#include "gvkit/codec/plane_coding.hpp"

namespace gvkit::codec {

enum class MotionSearchPattern {
  kFull,     // every integer vector in range (ties: the first in raster order of (dy, dx))
  kDiamond,  // from the better of zero and the rounded predictor, small-diamond steps until the
             // centre is best, then its diagonal neighbours (each vector measured once)
};

// Another plane of the frame searched together with the macroblock's own (joint motion search):
// its source and its interpolated reference, both the size of the searched plane.
struct JointMotionPlane {
  const SamplePlane* source = nullptr;
  const InterpolatedReference* reference = nullptr;
};

struct MotionSearchParams {
  MotionSearchPattern pattern = MotionSearchPattern::kFull;
  int range = 4;          // integer search: |dx|, |dy| <= range samples around zero (0..32)
  int subpel = 0;         // 0 (whole samples), 2 (refine to half) or 4 (to quarter samples)
  bool lossless = false;  // refinement by SAD instead of SATD
  double lambda = 1;      // cost of one motion bit in distortion units
  int max_abs_mv = 256;   // refinement limit on |vector component| (vector units)
  // Shared motion (format 1.4): the co-located first-plane vector costs its flag only (1 bit),
  // every other vector the flag and its differences; the refinement also tries it.
  bool has_shared = false;
  int shared_mv_x = 0, shared_mv_y = 0;  // vector units
  // Planes whose prediction error is added to the own plane's at every vector.
  std::span<const JointMotionPlane> joint;
};

struct MotionSearchResult {
  int mv_x = 0, mv_y = 0;              // the chosen vector (vector units)
  int whole_mv_x = 0, whole_mv_y = 0;  // the integer search's result (vector units)
};

// Bits of the signed Exp-Golomb code of v (the estimate of a motion vector difference's cost).
inline int signed_exp_golomb_bits(int v) {
  if (v == 0) return 1;
  int k = 0;
  uint32_t a = static_cast<uint32_t>(v < 0 ? -v : v) - 1;
  while (a >= (1u << k)) a -= 1u << k++;
  return 2 + 2 * k + 1;
}

// Estimated bits of vector (mx, my) against the predictor (px, py), shared motion included.
double motion_vector_bits(int mx, int my, int px, int py, const MotionSearchParams& params);

// The macroblock at (x0, y0) of src (same size as the reference); (px, py) is the motion vector
// predictor in vector units.
MotionSearchResult search_motion_16x16(const SamplePlane& src, const InterpolatedReference& ref,
                                       int x0, int y0, int px, int py,
                                       const MotionSearchParams& params);

}  // namespace gvkit::codec
