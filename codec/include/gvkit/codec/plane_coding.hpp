#pragma once
// Intra coding of one sample plane (B-bit samples, width and height multiples of 16) into one
// CABAC segment, and its mirror. The macroblock layer follows H.264's intra macroblocks: types
// I4x4 (9 modes, or 13 with the geometry modes), I8x8 (9 modes) and I16x16 (4 modes), a 4-bit
// coded block pattern, coded_block_flag per 4x4 block, and residual blocks coded with a
// significance map and unary/Exp-Golomb levels. Syntax and contexts: docs/bitstream.md.

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gvkit/codec/coding_stats.hpp"
#include "gvkit/codec/cross_plane.hpp"
#include "gvkit/codec/cross_plane_contexts.hpp"
#include "gvkit/codec/deblocking_params.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::codec {

class ReferenceInterpolationCache;  // interpolation_cache.hpp (encoder only)

struct PlaneCodingParams {
  int bit_depth = 16;     // 8..16
  int qp_prime = 0;       // QP + 6 (B - 8), 0..99; ignored when lossless
  bool lossless = false;  // transform bypass: residuals coded as they are
  bool geometry_modes = true;
  bool adaptive_levels = false;  // |level| - 2 as adaptive-order Exp-Golomb (for lossless)
  // With lossless (transform bypass): residuals quantized in the sample domain with the step
  // 2 near_lossless + 1, so every reconstructed sample is within near_lossless of the source
  // (0 = exact). 0..65535.
  int near_lossless = 0;
  // P planes: an inter macroblock may predict each 4x4 block as the motion-compensated
  // reference plus an intra prediction of the temporal difference (recon - reference) from the
  // block's neighbours (docs/bitstream.md 4.4).
  bool td_prediction = false;
  // P planes: 0 = whole-sample motion vectors; 2 or 4 = vectors in quarter samples (H.264
  // interpolation, docs/bitstream.md 4.4), which the encoder refines to half (2) or quarter (4)
  // sample precision around the best whole-sample vector. The decoder only tests != 0.
  int subpel = 0;
  // P planes, multiple reference frames (format 1.6, docs/bitstream.md 4.7): the number of
  // references (1..5); with more than one, every inter macroblock that is not a skip codes
  // ref_idx. The references are passed to encode_plane / decode_plane, nearest first.
  int ref_count = 1;
  // Format 1.6 (larger transforms, docs/bitstream.md 4.8): 8 or 16 lets plain inter and I16x16
  // macroblocks code their residual with an 8x8 (or a 16x16) transform, chosen per macroblock;
  // 4 = sixteen 4x4 blocks only (the syntax before 1.6). Lossy planes only.
  int max_transform = 4;
  // Format 1.7 (inter partitions, docs/bitstream.md 4.11), P planes: a plain inter macroblock
  // may split into two 16x8 or 8x16 partitions or four 8x8 ones, each with its own reference
  // and vector (vector predictors then read the motion per 8x8 block).
  bool partitions = false;
  // Format 1.8 (deblocking filter, docs/bitstream.md 4.12), lossy planes: the reconstruction is
  // filtered after the last macroblock (deblocking.hpp), as every reference and output is.
  bool deblocking = false;
  DeblockingParams deblock;
  // Format 1.11 (merge, docs/bitstream.md 4.14), P planes: a skip codes which of the predictor
  // and up to four neighbours' vectors it takes, a 16x16 inter macroblock whether it takes one
  // of those neighbours' vectors (merge_idx).
  bool merge = false;
  // Format 1.12 (TD16, docs/bitstream.md 4.15), P planes with td_prediction: a TD macroblock
  // codes whether it predicts the temporal difference with one 16x16 mode (an I16x16 mode, the
  // residual then as a plain inter macroblock's) instead of sixteen 4x4 ones.
  bool td16 = false;
  // Format 1.13 (quadratic intra, docs/bitstream.md 6.1): I16x16 and TD16 macroblocks not in
  // the first macroblock row or column may take the quadratic mode (quadratic_intra.hpp), coded
  // with one bin before the mode's two.
  bool quadratic_intra = false;
  bool allow_8x8 = true;  // encoder only: consider I8x8 macroblocks
  // Encoder only, lossy inter macroblocks: quantize with the inter dead zone and drop sparse
  // blocks of +-1 levels (decimation).
  bool inter_decimation = false;
  // Encoder only, P planes: try the predicted vector on its own before the search (a skip
  // found there is taken at once by the fast path).
  bool skip_check = false;
  // Encoder only, P planes without rdo: TD is tried again at the whole-sample search result
  // where TD at the sub-sample vector beat plain inter (with rdo and lossless always).
  bool td_whole_retry = true;
  // Encoder only, lossy planes: rate-distortion optimised quantization (rdo_quantization.hpp)
  // instead of the intra rounding and the inter dead zone.
  bool rdoq = false;
  bool rdo = true;  // encoder only: SSD + lambda * bits (else SATD-based decisions)
  // Encoder only, lossy planes with rdo: each sample's squared error in the SSD of the
  // rate-distortion decisions counts this many times (row-major over the plane's padded
  // width x height; null = once each).
  const std::vector<uint8_t>* distortion_weights = nullptr;
  // Encoder only, with rdo and larger transforms: a residual's transform sizes are tried from
  // the largest down, and the smaller ones are skipped once a size leaves no level or costs
  // more than the larger one.
  bool transform_early_exit = false;
  // Encoder only, with rdo: 4x4 intra blocks and I16x16 macroblocks code only this many modes,
  // those of the lowest SATD-based costs (0 = every mode).
  int intra_rdo_shortlist = 0;
  int search_range = 4;  // encoder only: full-search motion range (samples) of P planes
  // The segment ends with H.264's end-of-slice bin (a terminating 1) and flush. false (format
  // 1.10, segments of compact packets): it ends after the last macroblock's bins with the
  // shortest flush (CabacEncoder::finish_unterminated), about a byte less; the decoder knows the
  // macroblock count and checks only that it did not read past the data's allowance.
  bool end_of_plane_bin = true;
};

struct MotionField;

// A plane of samples in [0, 2^bit_depth - 1], row-major.
struct SamplePlane {
  int width = 0, height = 0;
  std::vector<uint16_t> samples;
  // Format 1.9 (temporal contexts, docs/bitstream.md 4.13): the context states the plane's
  // segment ended with, on planes encode_frame or decode_frame_packet reconstructed (null on
  // other planes); the same plane of a later P or B frame may start from them.
  std::shared_ptr<const CrossPlaneContextStates> final_contexts;
  // Format 1.11 (merge, docs/bitstream.md 4.14): the motion of a P plane encode_frame or
  // decode_frame_packet reconstructed (null on other planes); the same plane of a later P frame
  // takes its co-located vector as a merge candidate.
  std::shared_ptr<const MotionField> motion;
  // Format 1.14 (docs/bitstream.md 2.3): a plane of a half-resolution frame, as coded (before
  // upsampling); a P or B frame codes at the resolution of its references.
  bool half_resolution = false;
  uint16_t& at(int x, int y) { return samples[static_cast<size_t>(y) * width + x]; }
  uint16_t at(int x, int y) const { return samples[static_cast<size_t>(y) * width + x]; }
};

// The motion of a coded P plane, per macroblock in raster order: what the other planes of the
// frame may take over with one flag per macroblock (shared motion, docs/bitstream.md 4.5).
struct MotionField {
  int mbs_x = 0, mbs_y = 0;
  std::vector<uint8_t> inter;       // 1: inter (plain, skip or TD), 0: intra
  std::vector<uint8_t> skip;        // 1: skip
  std::vector<int16_t> mv_x, mv_y;  // the vector the macroblock used (inter only)
  std::vector<uint8_t> ref_idx;     // its reference (format 1.6; 0 with one reference)
};

struct PlaneEncodeResult {
  std::string bytes;           // the CABAC segment
  SamplePlane reconstruction;  // what the decoder will reconstruct
  PlaneCodingStats stats;      // where the segment's bits went
  MotionField motion;          // P planes: the macroblocks' motion
};

// Encoder only: more planes of the same frame (sources and their references, same size) whose
// prediction error the motion search of a P plane adds to its own, so that its vectors suit all
// of them (the first plane's search under shared motion).
struct JointSearchPlanes {
  std::vector<const SamplePlane*> sources, references;
  // Multiple reference frames: more_references[k - 1][j] is reference k of plane sources[j].
  std::vector<std::vector<const SamplePlane*>> more_references;
};

// plane.width and plane.height must be positive multiples of 16 (contract). With a reference
// (the previous frame's reconstruction of this plane, same size) the plane is coded as a P plane:
// each macroblock is intra or inter (motion, skip, TD). With `shared` (the motion of the frame's
// first plane, same macroblock grid; P planes only) a macroblock whose co-located one is inter
// may take over its vector with one context-coded flag (format 1.4). With params.ref_count > 1
// (format 1.6), more_references holds references 1 .. ref_count - 1 (the older anchors'
// reconstructions of this plane, nearest first, same size); `reference` is reference 0. With
// cross->source (Y and Z planes, format 1.6; the X plane's residual, same size) a macroblock may
// add a scaled copy of it to its residual (cross_plane.hpp); cross->residual_out receives the
// plane's own residual. `cache` (optional): where the references' interpolated planes are taken
// from and kept (interpolation_cache.hpp; the segment does not depend on it).
PlaneEncodeResult encode_plane(const SamplePlane& plane, const PlaneCodingParams& params,
                               const SamplePlane* reference = nullptr,
                               const MotionField* shared = nullptr,
                               const JointSearchPlanes* joint = nullptr,
                               const std::vector<const SamplePlane*>* more_references = nullptr,
                               const CrossPlaneLinks* cross = nullptr,
                               ReferenceInterpolationCache* cache = nullptr);

// Decodes a segment made by encode_plane with the same bit depth, QP, flags, shared motion and
// cross-plane source. Fails with a message naming the macroblock and the field when the data
// cannot be a valid segment. motion_out (optional, P planes) receives the plane's motion,
// cross->residual_out (optional) the plane's residual. With params.ref_count > 1,
// more_references must hold ref_count - 1 planes (as for encode_plane; contract).
Result<SamplePlane> decode_plane(std::string_view bytes, int width, int height,
                                 const PlaneCodingParams& params,
                                 const SamplePlane* reference = nullptr,
                                 const MotionField* shared = nullptr,
                                 MotionField* motion_out = nullptr,
                                 const std::vector<const SamplePlane*>* more_references = nullptr,
                                 const CrossPlaneLinks* cross = nullptr);

// B planes (format 1.5): each macroblock is intra, skip (direct without residual) or inter from
// reference0 (list 0: the anchor before in display order), reference1 (list 1: the anchor
// after) or the rounded average of both (bi), with a quarter- or whole-sample vector per list
// (direct: the predicted vectors). params.td_prediction is ignored (no TD in B planes); both
// references have the plane's size. `cache` as for encode_plane.
PlaneEncodeResult encode_b_plane(const SamplePlane& plane, const PlaneCodingParams& params,
                                 const SamplePlane& reference0, const SamplePlane& reference1,
                                 const CrossPlaneLinks* cross = nullptr,
                                 ReferenceInterpolationCache* cache = nullptr);
// Decodes a segment made by encode_b_plane; fails naming the macroblock and the field.
Result<SamplePlane> decode_b_plane(std::string_view bytes, int width, int height,
                                   const PlaneCodingParams& params, const SamplePlane& reference0,
                                   const SamplePlane& reference1,
                                   const CrossPlaneLinks* cross = nullptr);

}  // namespace gvkit::codec
