#pragma once
// Half-resolution coding (format 1.14, docs/bitstream.md 2.3): a frame whose packet type byte
// has bit 4 set codes its planes at ceil(W/2) x ceil(H/2) samples (padded to whole 16x16
// macroblocks); the decoder upsamples them 2x with a fixed 4-tap filter to W x H. Geometry
// images are smooth: at low rates a quarter of the samples costs far less than the detail it
// loses (docs/benchmarks.md, "Format 1.14: half resolution").

#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/codec/plane_coding.hpp"

namespace gvkit::codec {

// Coded samples along an axis of n pixels at half resolution: ceil(n / 2).
inline int half_size(int n) { return (n + 1) / 2; }

// The upsampling filter (normative): full-resolution pixel 2i + 1 lies at half-resolution
// position i + 1/4 and takes kHalfUpsampleTaps[k] x sample (i - 1 + k); pixel 2i lies at i - 1/4
// and takes the mirrored taps over samples i - 2 .. i + 1. Indices are clamped to the coded
// (unpadded) samples. Units of 1/64 (HEVC's chroma interpolation filter at a quarter sample).
inline constexpr int kHalfUpsampleTaps[4] = {-4, 54, 16, -2};

// Normative 2x upsampling of a half-resolution plane whose first half_size(width) x
// half_size(height) samples are coded: the horizontal pass keeps full precision (x64), the
// vertical one rounds ((sum + 2^11) >> 12) and clamps to [0, 2^bit_depth - 1]. Returns a
// width x height plane padded to multiples of 16 by repeating the last row and column.
SamplePlane upsample_half_plane(const SamplePlane& half, int width, int height, int bit_depth);
// The plain version of upsample_half_plane (which uses AVX2 where the processor has it and
// returns the same samples).
SamplePlane upsample_half_plane_reference(const SamplePlane& half, int width, int height,
                                          int bit_depth);

// The encoder's downsampling (not normative): the half-resolution samples whose upsampling is
// closest to `full`'s first width x height samples in least squares (separable: the 1-D
// pseudo-inverse of the upsampling filter along each axis), rounded and clamped to
// [0, 2^bit_depth - 1], padded to multiples of 16. `full` is filled outside the domain
// (quantize_geometry), so its smooth filler takes part like any other sample.
SamplePlane downsample_plane(const SamplePlane& full, int width, int height, int bit_depth);

// Normative 2x2 mean (format 1.14, the anchor after a B frame when its anchors differ in
// resolution): sample (i, j) = (the four pixels 2i..2i+1 x 2j..2j+1, indices clamped to the
// first width x height samples, summed + 2) >> 2, padded to multiples of 16.
SamplePlane halve_plane_mean(const SamplePlane& full, int width, int height);

// Where the half-resolution planes cover the domain: a sample is in it when any of its 2x2
// pixels is (CV_8U, half_size(rows) x half_size(cols), 255 inside).
cv::Mat half_domain_mask(const cv::Mat& mask);

// Mean squared difference (squared samples) over the domain pixels of planes X, Y, Z of a and b
// (at least width x height each).
double domain_mse(const std::vector<SamplePlane>& a, const std::vector<SamplePlane>& b,
                  const cv::Mat& mask);

}  // namespace gvkit::codec
