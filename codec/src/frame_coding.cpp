#include "gvkit/codec/frame_coding.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "gvkit/codec/byte_io.hpp"
#include "gvkit/codec/crc32.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/half_resolution.hpp"
#include "gvkit/codec/plane_coding.hpp"
#include "gvkit/codec/value_prediction.hpp"
#include "outline_weights.hpp"

namespace gvkit::codec {
namespace {

const char* const kPlaneNames[4] = {"X", "Y", "Z", "T"};

// EncoderOptions::intra_rdo: the modes coded per 4x4 block and I16x16 macroblock. On the ICT
// face (fast preset, BD-rate against x265's logged points): 2 and 2 +22.99 %, 4x4 blocks 4 and
// I16x16 all 4 +22.79 %, all +22.38 %, 1 and 1 +24.61 %, where the 2 / 2 list costs the least
// speed (docs/benchmarks.md, "Fast preset: RDO in I frames").
constexpr int kFastIntraRdoShortlist = 2;

// Frame-level syntax of the payload before the plane segments (docs/bitstream.md 2.1).
struct FrameSyntax {
  int near_lossless = 0;
  ValueTransform value_transform;
  int plane_qp_offset[4] = {0, 0, 0, 0};  // X, Y, Z and the texture plane T
  int ref_count = 1;                      // format 1.6: P frames with flags2 bit 1, 2..5
  int max_transform = 4;                  // format 1.6 (flags2 bit 2): 8 or 16
  bool partitions = false;                // format 1.7: P frames with flags2 bit 5
  bool deblocking = false;                // format 1.8: flags2 bit 6
  DeblockingParams deblock;
  bool merge = false;            // format 1.11: the payload's first byte, bit 5
  bool td16 = false;             // format 1.12: the payload's first byte, bit 6
  bool quadratic_intra = false;  // format 1.13: the payload's first byte, bit 7
};

// What plane `plane` (0 = X, 1 = Y, 2 = Z, 3 = texture) of a frame exchanges with X and with the
// reference: with cross-plane prediction (flags2 bit 3) X records its residual and Y and Z read
// it; every plane records its final context states in states[plane], which Y and Z start from
// with cross-plane contexts (bit 4, X's states), and every plane of a frame with temporal
// contexts (bit 7) starts from the same plane's final states in `temporal` (reference 0); a P
// plane takes the same plane's motion in `p_reference` (reference 0, before any value
// transform) as merge's co-located candidate (format 1.11). The same for the encoder and the
// decoder.
CrossPlaneLinks plane_links(size_t plane, bool cross_plane, bool cross_contexts,
                            const std::vector<SamplePlane>* temporal,
                            CrossPlaneResidual* x_residual, CrossPlaneContextStates* states,
                            const std::vector<SamplePlane>* p_reference) {
  CrossPlaneLinks links;
  if (p_reference) links.reference_motion = (*p_reference)[plane].motion.get();  // format 1.11
  const bool x = plane == 0, y_or_z = plane == 1 || plane == 2;
  if (cross_plane && x) links.residual_out = x_residual;
  if (cross_plane && y_or_z) links.source = x_residual;
  links.contexts_out = &states[plane];
  if (temporal)
    links.contexts = (*temporal)[plane].final_contexts.get();
  else if (cross_contexts && y_or_z)
    links.contexts = &states[0];
  return links;
}

// Whether every plane of `reference` carries the final context states temporal contexts start
// from (format 1.9).
bool has_final_contexts(const std::vector<SamplePlane>& reference) {
  return std::all_of(reference.begin(), reference.end(),
                     [](const SamplePlane& p) { return p.final_contexts != nullptr; });
}

PlaneCodingParams plane_params(const SequenceInfo& info, int plane, uint8_t flags, int qp,
                               const FrameSyntax& syntax) {
  PlaneCodingParams p;
  p.bit_depth = plane < 3 ? info.bit_depth : 8;
  p.lossless = (flags & format::kFrameLossless) != 0;
  p.geometry_modes = (flags & format::kFrameGeometryModes) != 0;
  p.adaptive_levels = (flags & format::kFrameAdaptiveLevels) != 0;
  p.td_prediction = (flags & format::kFrameTdPrediction) != 0;
  p.subpel = (flags & format::kFrameQuarterPel) != 0 ? 4 : 0;
  p.ref_count = syntax.ref_count;
  p.max_transform = syntax.max_transform;
  p.partitions = syntax.partitions;
  p.deblocking = syntax.deblocking;  // format 1.8
  p.deblock = syntax.deblock;
  p.merge = syntax.merge;                      // format 1.11
  p.td16 = syntax.td16;                        // format 1.12
  p.quadratic_intra = syntax.quadratic_intra;  // format 1.13
  if (plane < 3) p.near_lossless = syntax.near_lossless;
  qp += syntax.plane_qp_offset[std::min(plane, 3)];
  p.qp_prime = std::clamp(qp + 6 * (p.bit_depth - 8), 0, 51 + 6 * (p.bit_depth - 8));
  return p;
}

// Runs job(i) for i in [0, count) on up to `threads` threads; each i writes only its own slot, so
// the result does not depend on the thread count.
template <class Job>
void run_parallel(int count, int threads, const Job& job) {
  const int n = std::min(count, threads);
  if (n <= 1) {
    for (int i = 0; i < count; ++i) job(i);
    return;
  }
  std::atomic<int> next{0};
  const auto worker = [&] {
    for (int i = next++; i < count; i = next++) job(i);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
}

// Sum over the domain pixels and the X, Y, Z planes of |a - b|.
double domain_sad(const std::vector<SamplePlane>& a, const std::vector<SamplePlane>& b,
                  const cv::Mat& mask) {
  double sum = 0;
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* m = mask.ptr<uint8_t>(y);
    for (int x = 0; x < mask.cols; ++x)
      if (m[x])
        for (int p = 0; p < 3; ++p) sum += std::abs(a[p].at(x, y) - b[p].at(x, y));
  }
  return sum;
}

}  // namespace

int near_lossless_delta(const SequenceInfo& info, double max_error_mm) {
  if (!(max_error_mm > 0)) return 0;
  // Per axis: input rounding (<= step / 2) plus the residual quantizer (<= delta steps); the
  // Euclidean point error is at most sqrt(3) (delta + 1/2) step. 1e-4 mm is kept for the float
  // storage of input and output.
  const double d = (max_error_mm - 1e-4) / (std::sqrt(3.0) * info.step_mm()) - 0.5;
  if (d < 0) return -1;
  return static_cast<int>(std::min(std::floor(d), 65535.0));
}

namespace {

int plane_bit_depth(const SequenceInfo& info, size_t plane) {
  return plane < 3 ? info.bit_depth : 8;
}

// Format 1.14: the encoder's half-resolution planes of full-resolution ones, and the decoder's
// full-resolution planes of half-resolution ones (half_resolution.hpp).
std::vector<SamplePlane> downsample_planes(const std::vector<SamplePlane>& planes,
                                           const SequenceInfo& info) {
  std::vector<SamplePlane> half;
  for (size_t i = 0; i < planes.size(); ++i) {
    half.push_back(downsample_plane(planes[i], info.width, info.height, plane_bit_depth(info, i)));
    half.back().half_resolution = true;
  }
  return half;
}
std::vector<SamplePlane> upsample_planes(const std::vector<SamplePlane>& half,
                                         const SequenceInfo& info) {
  std::vector<SamplePlane> full;
  for (size_t i = 0; i < half.size(); ++i)
    full.push_back(upsample_half_plane(half[i], info.width, info.height, plane_bit_depth(info, i)));
  return full;
}

// A B frame's anchors at two resolutions (format 1.14: a resolution change at the I frame after
// it): the anchor after it at the resolution of the anchor before it, by the normative 2x
// upsampling or 2x2 mean (docs/bitstream.md 2.3).
std::vector<SamplePlane> at_resolution(const std::vector<SamplePlane>& planes, bool half,
                                       const SequenceInfo& info) {
  if (half) {
    std::vector<SamplePlane> out;
    for (const SamplePlane& plane : planes) {
      out.push_back(halve_plane_mean(plane, info.width, info.height));
      out.back().half_resolution = true;
    }
    return out;
  }
  return upsample_planes(planes, info);
}

// encode_frame with its coded planes given: the quantized frame, or with `half` (format 1.14)
// its half-resolution planes.
EncodedFrame encode_planes(const std::vector<SamplePlane>& planes, bool half,
                           const SequenceInfo& info, const EncoderOptions& options,
                           uint32_t frame_number, int delta,
                           const std::vector<SamplePlane>* reference,
                           const std::vector<SamplePlane>* reference1,
                           const std::vector<const std::vector<SamplePlane>*>* older,
                           ReferenceInterpolationCache* cache) {
  format::PacketHeader header;
  header.compact = true;          // every 2.0 packet
  header.half_resolution = half;  // packet type bit 4
  // The domain at the coded resolution (value prediction's fit).
  const cv::Mat mask = half ? half_domain_mask(info.domain_mask) : info.domain_mask;
  const bool bidirectional = reference1 != nullptr;
  header.type = bidirectional
                    ? format::FrameType::kBidirectional
                    : (reference ? format::FrameType::kPredicted : format::FrameType::kIntra);
  GVKIT_CHECK(!reference || reference->size() == planes.size());
  GVKIT_CHECK(!reference1 || (reference && reference1->size() == planes.size()));
  // P-frame tools B frames do not have: TD prediction, value prediction, shared motion.
  const bool p_frame = reference && !bidirectional;
  const bool bypass = options.bypass();
  FrameSyntax syntax;
  syntax.near_lossless = delta;
  header.flags =
      static_cast<uint8_t>((bypass ? format::kFrameLossless | format::kFrameAdaptiveLevels : 0) |
                           (options.geometry_modes ? format::kFrameGeometryModes : 0) |
                           (delta > 0 ? format::kFrameNearLossless : 0) |
                           (p_frame && options.td_prediction ? format::kFrameTdPrediction : 0) |
                           (reference && options.subpel ? format::kFrameQuarterPel : 0));
  if (p_frame && options.shared_motion) header.flags2 |= format::kFrame2SharedMotion;
  // Multiple reference frames (format 1.6): the nearest options.reference_frames() anchors
  // since the last I frame (reference, then `older`, nearest first).
  if (p_frame && options.reference_frames() > 1 && older && !older->empty()) {
    syntax.ref_count =
        std::min<int>(options.reference_frames(), 1 + static_cast<int>(older->size()));
    for (int k = 0; k + 1 < syntax.ref_count; ++k)
      GVKIT_CHECK((*older)[k] && (*older)[k]->size() == planes.size());
    header.flags2 |= format::kFrame2MultiRef;
  }
  if (options.large_transforms()) {
    header.flags2 |= format::kFrame2LargeTransforms;
    syntax.max_transform = options.max_transform;
  }
  if (options.cross_plane) header.flags2 |= format::kFrame2CrossPlane;  // format 1.6
  // Format 1.7: cross-plane contexts.
  // Format 1.9: temporal contexts in P and B frames (instead of cross-plane contexts there).
  const bool temporal = options.temporal_contexts && reference && has_final_contexts(*reference);
  if (temporal)
    header.flags2 |= format::kFrame2TemporalContexts;
  else if (options.cross_plane_contexts)
    header.flags2 |= format::kFrame2CrossPlaneContexts;
  if (p_frame && options.use_partitions()) {  // format 1.7
    header.flags2 |= format::kFrame2Partitions;
    syntax.partitions = true;
  }
  // Format 1.11: merge, when the reference carries what the decoder's will (planes that
  // encode_frame or decode_frame_packet reconstructed: final context states, and motion when
  // that frame was a P frame).
  syntax.merge = p_frame && options.merge && has_final_contexts(*reference);
  // Format 1.12: TD16, in P frames with TD prediction.
  syntax.td16 = p_frame && options.td16 && options.td_prediction;
  syntax.quadratic_intra = options.quadratic_intra;  // format 1.13: every frame
  if (options.deblocking && !bypass) {               // format 1.8
    header.flags2 |= format::kFrame2Deblocking;
    syntax.deblocking = true;
    syntax.deblock = options.deblock;
  }
  // Half resolution: 6 QP finer (a coded sample stands for four pixels: lambda / 4 per sample).
  header.qp = bypass
                  ? 0
                  : std::clamp(options.qp - (half ? 6 : 0) + (reference ? options.p_qp_offset : 0) +
                                   (bidirectional ? options.b_qp_offset : 0),
                               -6 * (info.bit_depth - 8), 51);
  header.frame_number = frame_number;
  // Value-domain prediction: fit and apply the transform; signalled only when not the identity.
  std::vector<SamplePlane> transformed;
  const std::vector<SamplePlane>* prediction_ref = reference;
  bool try_without_transform = false;
  if (p_frame && options.value_prediction != ValuePrediction::kNone) {
    syntax.value_transform =
        fit_value_transform(planes, *reference, mask, options.value_prediction, info.bit_depth);
    if (!syntax.value_transform.is_identity()) {
      transformed = apply_value_transform(*reference, syntax.value_transform, info.bit_depth);
      // Tried only when it brings the reference clearly closer to the frame (sum of absolute
      // differences over the domain), and then kept only when the frame costs less with it.
      if (domain_sad(planes, transformed, mask) < 0.9 * domain_sad(planes, *reference, mask)) {
        header.flags |= format::kFrameValuePrediction;
        prediction_ref = &transformed;
        try_without_transform = true;
      }
    }
  }
  if (!bypass) {
    for (int i = 0; i < 3; ++i) syntax.plane_qp_offset[i] = options.plane_qp_offset[i];
    // The texture plane at options.texture_qp in I frames (the frame QP's offsets for P and B
    // frames and half resolution apply to it as to the geometry).
    if (planes.size() == 4 && options.texture_qp >= 0)
      syntax.plane_qp_offset[3] = options.texture_qp - options.qp;
    for (int i = 0; i < 4; ++i)
      if (syntax.plane_qp_offset[i] != 0) header.flags |= format::kFramePlaneQp;
  }
  // Lossy frames: the outline's samples weigh outline_weight times in the SSD of the decisions.
  const std::vector<uint8_t> weights =
      bypass || options.outline_weight <= 1
          ? std::vector<uint8_t>()
          : outline_weights(mask, planes[0].width, planes[0].height, options.outline_weight);
  const bool shared_motion = (header.flags2 & format::kFrame2SharedMotion) != 0;
  const bool cross_plane = (header.flags2 & format::kFrame2CrossPlane) != 0;
  const bool cross_contexts = (header.flags2 & format::kFrame2CrossPlaneContexts) != 0;  // 1.7
  const auto code_planes = [&](uint8_t flags, const std::vector<SamplePlane>* ref) {
    std::vector<PlaneEncodeResult> coded(planes.size());
    // Cross-plane prediction: X keeps its residual, which Y and Z predict from.
    CrossPlaneResidual x_residual;
    // Every plane's final context states (format 1.7: X's are Y's and Z's initial ones).
    CrossPlaneContextStates states[4];
    const auto code = [&](int i) {
      PlaneCodingParams p = plane_params(info, i, flags, header.qp, syntax);
      p.rdo = options.preset == Preset::kSlow;
      p.allow_8x8 = options.preset == Preset::kSlow;
      if (!p.rdo && options.intra_rdo && !ref && !bypass) {  // fast preset, lossy I frames
        p.rdo = true;
        p.intra_rdo_shortlist = kFastIntraRdoShortlist;
      }
      if (!weights.empty() && i < 3) p.distortion_weights = &weights;
      if (options.preset == Preset::kSlow && !bypass) {
        p.intra_rdo_shortlist = options.rdo_shortlist;
        p.transform_early_exit = options.transform_early_exit;
      }
      p.search_range = options.search_range;
      p.inter_decimation = options.inter_decimation;
      p.rdoq = options.rdoq;
      p.skip_check = options.skip_check;
      p.td_whole_retry = options.td_whole_retry;
      p.end_of_plane_bin = false;               // compact packets
      if (p.subpel) p.subpel = options.subpel;  // the encoder's refinement precision
      const MotionField* shared = shared_motion && (i == 1 || i == 2) ? &coded[0].motion : nullptr;
      // Multiple references: this plane of references 1 .. ref_count - 1 (value prediction
      // maps reference 0 only).
      std::vector<const SamplePlane*> more;
      for (int k = 0; k + 1 < syntax.ref_count; ++k) more.push_back(&(*(*older)[k])[i]);
      // Shared motion: X's vectors are searched on the prediction error of X, Y and Z together.
      JointSearchPlanes joint;
      if (shared_motion && (options.joint_motion_search || bypass) && i == 0 && ref)
        for (int j = 1; j < 3; ++j) {
          joint.sources.push_back(&planes[j]);
          joint.references.push_back(&(*ref)[j]);
        }
      if (!joint.sources.empty())
        for (int k = 0; k + 1 < syntax.ref_count; ++k)
          joint.more_references.push_back({&(*(*older)[k])[1], &(*(*older)[k])[2]});
      const CrossPlaneLinks links =
          plane_links(i, cross_plane, cross_contexts, temporal ? reference : nullptr, &x_residual,
                      states, p_frame ? reference : nullptr);
      if (bidirectional)
        coded[i] = encode_b_plane(planes[i], p, (*ref)[i], (*reference1)[i], &links, cache);
      else
        coded[i] = encode_plane(planes[i], p, ref ? &(*ref)[i] : nullptr, shared, &joint,
                                more.empty() ? nullptr : &more, &links, cache);
      coded[i].reconstruction.final_contexts =
          std::make_shared<const CrossPlaneContextStates>(states[i]);
      if (p_frame)  // format 1.11: the next P frame's co-located merge candidates
        coded[i].reconstruction.motion = std::make_shared<const MotionField>(coded[i].motion);
    };
    if (!shared_motion && !cross_plane && !cross_contexts) {
      run_parallel(static_cast<int>(planes.size()), options.threads, code);
    } else {
      // Shared motion and cross-plane prediction: X first (its motion is Y's and Z's candidate,
      // its residual their cross-plane source, its final context states their initial ones
      // (1.7)), beside the texture plane, which takes nothing from X; then Y and Z in parallel.
      const int first = planes.size() > 3 ? 2 : 1;  // X, and T when there is one
      run_parallel(first, options.threads, [&](int i) { code(i == 0 ? 0 : 3); });
      run_parallel(2, options.threads, [&](int i) { code(i + 1); });
    }
    return coded;
  };
  std::vector<PlaneEncodeResult> coded = code_planes(header.flags, prediction_ref);
  if (try_without_transform) {
    // Rate-distortion cost of the frame: SSD of the samples + lambda x bits, with the lambda
    // of the macroblock decisions.
    const double step = 2.0 * delta + 1.0;
    const double lambda =
        bypass ? (delta > 0 ? 0.136 * step * step : 1.0)
               : 0.85 * std::pow(2.0, (header.qp + 6 * (info.bit_depth - 8) - 12) / 3.0);
    const auto cost = [&](const std::vector<PlaneEncodeResult>& c, double extra_bits) {
      double ssd = 0, bits = extra_bits;
      for (size_t i = 0; i < c.size(); ++i) {
        bits += 8.0 * static_cast<double>(c[i].bytes.size());
        for (size_t k = 0; k < planes[i].samples.size(); ++k) {
          const double d = planes[i].samples[k] - c[i].reconstruction.samples[k];
          ssd += d * d;
        }
      }
      return ssd + lambda * bits;
    };
    ByteWriter transform_syntax;
    write_value_transform(transform_syntax, syntax.value_transform);
    const auto without_flags = static_cast<uint8_t>(header.flags & ~format::kFrameValuePrediction);
    std::vector<PlaneEncodeResult> plain = code_planes(without_flags, reference);
    if (cost(plain, 0) <= cost(coded, 8.0 * static_cast<double>(transform_syntax.size()))) {
      coded = std::move(plain);
      header.flags = without_flags;
    }
  }
  ByteWriter payload;
  payload.u8(static_cast<uint8_t>(planes.size() | format::kPayloadCompactSegments |
                                  (syntax.merge ? format::kPayloadMerge : 0) |
                                  (syntax.td16 ? format::kPayloadTd16 : 0) |
                                  (syntax.quadratic_intra ? format::kPayloadQuadraticIntra : 0)));
  if (header.flags & format::kFrameNearLossless) payload.u16(static_cast<uint16_t>(delta));
  if (header.flags & format::kFrameValuePrediction)
    write_value_transform(payload, syntax.value_transform);
  if (header.flags & format::kFramePlaneQp)
    for (size_t i = 0; i < planes.size(); ++i)
      payload.u8(static_cast<uint8_t>(syntax.plane_qp_offset[i]));
  if (header.flags2 & format::kFrame2MultiRef) payload.u8(static_cast<uint8_t>(syntax.ref_count));
  if (header.flags2 & format::kFrame2LargeTransforms)
    payload.u8(static_cast<uint8_t>(syntax.max_transform));
  if (header.flags2 & format::kFrame2Deblocking) {  // format 1.8
    payload.u8(static_cast<uint8_t>(syntax.deblock.beta));
    payload.u8(static_cast<uint8_t>(syntax.deblock.tc));
  }
  std::vector<SamplePlane> recon;
  EncodedFrame out;
  for (auto& c : coded) {
    if (&c != &coded.back())  // compact sizes: the last segment takes the rest
      payload.varint(c.bytes.size());
    payload.bytes(c.bytes);
    recon.push_back(std::move(c.reconstruction));
    out.plane_stats.push_back(c.stats);
  }
  header.payload_size = static_cast<uint32_t>(payload.size());
  header.payload_crc = crc32(payload.str());
  out.packet = format::write_packet_header(header) + payload.str();
  for (SamplePlane& plane : recon) plane.half_resolution = half;
  out.reconstruction =
      dequantize_geometry(half ? upsample_planes(recon, info) : recon, info, frame_number);
  out.planes = std::move(recon);
  return out;
}

}  // namespace

Result<EncodedFrame> encode_frame(const GeometryImage& image, const SequenceInfo& info,
                                  const EncoderOptions& options, uint32_t frame_number,
                                  const std::vector<SamplePlane>* reference,
                                  const std::vector<SamplePlane>* reference1,
                                  const std::vector<const std::vector<SamplePlane>*>* older,
                                  ReferenceInterpolationCache* cache) {
  const std::string name = "frame " + std::to_string(frame_number);
  if (image.xyz_mm.rows != info.height || image.xyz_mm.cols != info.width)
    return invalid_argument(name + ": size differs from the sequence's");
  GVKIT_RETURN_IF_ERROR(image.check().with_context(name));
  if (info.has_texture && image.texture.empty())
    return invalid_argument(name + ": texture missing (the sequence has a texture plane)");
  const int delta = near_lossless_delta(info, options.max_error_mm);
  if (delta < 0)
    return invalid_argument(
        "max error " + std::to_string(options.max_error_mm) + " mm is below the " +
        std::to_string(info.bit_depth) + "-bit quantization error (" +
        std::to_string(std::sqrt(3.0) * 0.5 * info.step_mm()) + " mm); raise --bit-depth");
  const std::vector<SamplePlane> planes = quantize_geometry(image, info);
  const auto encode = [&](const std::vector<SamplePlane>& coded, bool half) {
    return encode_planes(coded, half, info, options, frame_number, delta, reference, reference1,
                         older, cache);
  };
  // Format 1.14: P and B frames code at their references' resolution; an I frame as the options
  // say.
  if (reference) {
    const bool half = (*reference)[0].half_resolution;
    if (half && options.bypass())
      return invalid_argument(name +
                              ": lossless or max-error coding from a half-resolution reference");
    std::vector<SamplePlane> converted;
    if (reference1 && (*reference1)[0].half_resolution != half) {
      converted = at_resolution(*reference1, half, info);
      reference1 = &converted;
    }
    return encode(half ? downsample_planes(planes, info) : planes, half);
  }
  if (!options.half_resolution_allowed()) return encode(planes, false);
  if (options.resolution == Resolution::kHalf) return encode(downsample_planes(planes, info), true);
  // Automatic: half resolution where halving and upsampling the frame loses no more than coding
  // it at full resolution does (mean squared sample error over the domain, X, Y, Z).
  EncodedFrame full = encode(planes, false);
  std::vector<SamplePlane> halved = downsample_planes(planes, info);
  const double resampling = domain_mse(planes, upsample_planes(halved, info), info.domain_mask);
  if (resampling > domain_mse(planes, full.planes, info.domain_mask)) return full;
  return encode(halved, true);
}

Result<int> packet_reference_count(std::string_view packet) {
  GVKIT_ASSIGN_OR_RETURN(const format::PacketHeader header, format::read_packet_header(packet));
  if (header.type == format::FrameType::kIntra) return 0;
  if (header.type == format::FrameType::kBidirectional) return 2;
  if (!(header.flags2 & format::kFrame2MultiRef)) return 1;
  if (packet.size() - header.header_size < header.payload_size)
    return corrupt_data("payload truncated");
  ByteReader r(packet.substr(header.header_size, header.payload_size));
  r.u8();  // plane count and payload flags
  if (header.flags & format::kFrameNearLossless) r.u16();
  if (header.flags & format::kFrameValuePrediction) {
    auto transform = read_value_transform(r);
    if (!transform.is_ok()) return transform.status();
  }
  if (header.flags & format::kFramePlaneQp)
    for (int i = 0; i < 3; ++i) r.u8();
  const int ref_count = r.u8();
  if (!r.ok()) return corrupt_data("ref_count missing");
  return ref_count;
}

Result<std::vector<SamplePlane>> decode_frame_planes(
    std::string_view packet, const SequenceInfo& info, const std::vector<SamplePlane>* reference,
    const std::vector<SamplePlane>* reference1,
    const std::vector<const std::vector<SamplePlane>*>* older, bool texture_qp_offset) {
  GVKIT_ASSIGN_OR_RETURN(const format::PacketHeader header, format::read_packet_header(packet));
  if (packet.size() - header.header_size < header.payload_size)
    return corrupt_data("payload truncated");
  const std::string_view payload = packet.substr(header.header_size, header.payload_size);
  if (crc32(payload.data(), payload.size()) != header.payload_crc)
    return corrupt_data("payload CRC mismatch");
  if (header.type != format::FrameType::kIntra && header.type != format::FrameType::kPredicted &&
      header.type != format::FrameType::kBidirectional)
    return corrupt_data("frame type " + std::to_string(static_cast<int>(header.type)));
  const bool bidirectional = header.type == format::FrameType::kBidirectional;
  const bool predicted = header.type == format::FrameType::kPredicted || bidirectional;
  const bool p_frame = predicted && !bidirectional;
  const size_t expected_planes = info.has_texture ? 4u : 3u;
  if (predicted && (!reference || reference->size() != expected_planes))
    return corrupt_data(bidirectional ? "B frame without the anchor frame before it"
                                      : "P frame without a reference frame");
  if (bidirectional && (!reference1 || reference1->size() != expected_planes))
    return corrupt_data("B frame without the anchor frame after it");
  if (bidirectional &&
      ((header.flags & (format::kFrameValuePrediction | format::kFrameTdPrediction)) ||
       (header.flags2 & format::kFrame2SharedMotion)))
    return corrupt_data(
        "frame flags: P-frame tools (value, TD prediction or shared motion) in a "
        "B frame");
  const bool lossless = (header.flags & format::kFrameLossless) != 0;
  const bool half = header.half_resolution;  // format 1.14
  if (half && lossless) return corrupt_data("packet type: half resolution in a lossless frame");
  if (predicted && (*reference)[0].half_resolution != half)
    return corrupt_data(std::string("frame at ") + (half ? "half" : "full") +
                        " resolution, its reference frame at " + (half ? "full" : "half"));
  // Format 1.14: a B frame whose anchor after it has the other resolution (a change at that I
  // frame) predicts from it converted to its own.
  std::vector<SamplePlane> converted;
  if (bidirectional && (*reference1)[0].half_resolution != half) {
    converted = at_resolution(*reference1, half, info);
    reference1 = &converted;
  }
  if ((header.flags & format::kFrameNearLossless) && !lossless)
    return corrupt_data("frame flags: near-lossless without transform bypass");
  if ((header.flags & format::kFramePlaneQp) && lossless)
    return corrupt_data("frame flags: plane QP offsets in a lossless frame");
  if ((header.flags &
       (format::kFrameValuePrediction | format::kFrameTdPrediction | format::kFrameQuarterPel)) &&
      !predicted)
    return corrupt_data("frame flags: inter tools in an intra frame");
  const bool temporal = (header.flags2 & format::kFrame2TemporalContexts) != 0;  // format 1.9
  if (temporal && !predicted)
    return corrupt_data("frame flags2: temporal contexts in an intra frame");
  if (temporal && (header.flags2 & format::kFrame2CrossPlaneContexts))
    return corrupt_data("frame flags2: temporal contexts with cross-plane contexts");
  if (temporal && !has_final_contexts(*reference))
    return failed_precondition(
        "temporal contexts: the reference frame's planes carry no final context states (decode "
        "it with decode_frame_packet)");
  const bool shared_motion = (header.flags2 & format::kFrame2SharedMotion) != 0;
  if (shared_motion && !predicted)
    return corrupt_data("frame flags2: shared motion in an intra frame");
  const bool multi_ref = (header.flags2 & format::kFrame2MultiRef) != 0;
  if (multi_ref && !predicted)
    return corrupt_data("frame flags2: multiple reference frames in an intra frame");
  if ((header.flags2 & format::kFrame2LargeTransforms) && lossless)
    return corrupt_data("frame flags2: larger transforms in a lossless frame");
  if ((header.flags2 & format::kFrame2Partitions) && header.type != format::FrameType::kPredicted)
    return corrupt_data("frame flags2: inter partitions outside a P frame");
  if ((header.flags2 & format::kFrame2Deblocking) && lossless)
    return corrupt_data("frame flags2: deblocking in a lossless frame");
  if (!lossless && (header.qp < -6 * (info.bit_depth - 8) || header.qp > 51))
    return corrupt_data("qp " + std::to_string(header.qp) + " out of range");
  ByteReader r(payload);
  const uint8_t planes_byte = r.u8();
  if (planes_byte & ~format::kPayloadKnown)
    return corrupt_data("payload flags: unknown bits " + std::to_string(planes_byte >> 4));
  const size_t plane_count = planes_byte & format::kPayloadPlaneCount;
  const bool compact = (planes_byte & format::kPayloadCompactSegments) != 0;  // format 1.9
  const size_t expected = info.has_texture ? 4 : 3;
  if (plane_count != expected)
    return corrupt_data("plane count " + std::to_string(plane_count) + " (header says " +
                        std::to_string(expected) + ")");
  FrameSyntax syntax;
  syntax.partitions = (header.flags2 & format::kFrame2Partitions) != 0;  // format 1.7
  syntax.merge = (planes_byte & format::kPayloadMerge) != 0;             // format 1.11
  if (syntax.merge && !p_frame) return corrupt_data("payload flags: merge outside a P frame");
  syntax.td16 = (planes_byte & format::kPayloadTd16) != 0;                       // format 1.12
  syntax.quadratic_intra = (planes_byte & format::kPayloadQuadraticIntra) != 0;  // format 1.13
  if (syntax.td16 && !(p_frame && (header.flags & format::kFrameTdPrediction)))
    return corrupt_data("payload flags: TD16 outside a P frame with TD prediction");
  if (syntax.merge && !has_final_contexts(*reference))
    return failed_precondition(
        "merge: the reference frame's planes carry no motion record (decode it with "
        "decode_frame_packet)");
  if (header.flags & format::kFrameNearLossless) {
    syntax.near_lossless = r.u16();
    if (!r.ok() || syntax.near_lossless == 0)
      return corrupt_data("near-lossless delta missing or 0");
  }
  // The coded planes' size: the frame's, or (format 1.14) half of it, padded to whole
  // macroblocks.
  const int pw = ((half ? half_size(info.width) : info.width) + 15) / 16 * 16;
  const int ph = ((half ? half_size(info.height) : info.height) + 15) / 16 * 16;
  std::vector<SamplePlane> transformed;
  const std::vector<SamplePlane>* prediction_ref = predicted ? reference : nullptr;
  if (header.flags & format::kFrameValuePrediction) {
    auto transform = read_value_transform(r);
    if (!transform.is_ok()) return transform.status();
    syntax.value_transform = *transform;
    for (int i = 0; i < 3; ++i)
      if ((*reference)[i].width != pw || (*reference)[i].height != ph)
        return corrupt_data("reference frame size differs");
    transformed = apply_value_transform(*reference, syntax.value_transform, info.bit_depth);
    prediction_ref = &transformed;
  }
  if (header.flags & format::kFramePlaneQp) {
    for (int i = 0; i < 3; ++i) {
      syntax.plane_qp_offset[i] = static_cast<int8_t>(r.u8());
      if (!r.ok() || syntax.plane_qp_offset[i] < -12 || syntax.plane_qp_offset[i] > 12)
        return corrupt_data("plane QP offset missing or out of range (-12..12)");
    }
    if (plane_count == 4 && texture_qp_offset) {  // format 2.0: the texture plane's
      syntax.plane_qp_offset[3] = static_cast<int8_t>(r.u8());
      if (!r.ok() || syntax.plane_qp_offset[3] < -51 || syntax.plane_qp_offset[3] > 99)
        return corrupt_data("texture QP offset missing or out of range (-51..99)");
    }
  }
  // Multiple reference frames (format 1.6): ref_count 2..5, each an anchor the caller holds.
  std::vector<std::vector<const SamplePlane*>> more(plane_count);
  if (multi_ref) {
    syntax.ref_count = r.u8();
    if (!r.ok()) return corrupt_data("ref_count missing");
    if (syntax.ref_count < 2 || syntax.ref_count > format::kMaxReferenceFrames)
      return corrupt_data("ref_count " + std::to_string(syntax.ref_count) + " out of range (2.." +
                          std::to_string(format::kMaxReferenceFrames) + ")");
    const size_t available = 1 + (older ? older->size() : 0);
    if (static_cast<size_t>(syntax.ref_count) > available)
      return corrupt_data("ref_count " + std::to_string(syntax.ref_count) + " names more " +
                          "reference frames than the " + std::to_string(available) +
                          " anchor frames since the last intra frame");
    for (int k = 0; k + 1 < syntax.ref_count; ++k) {
      const std::vector<SamplePlane>* refk = (*older)[k];
      if (!refk || refk->size() != expected_planes)
        return corrupt_data("reference frame " + std::to_string(k + 1) + " missing");
      for (size_t i = 0; i < plane_count; ++i) more[i].push_back(&(*refk)[i]);
    }
  }
  if (header.flags2 & format::kFrame2LargeTransforms) {
    syntax.max_transform = r.u8();
    if (!r.ok() || (syntax.max_transform != 8 && syntax.max_transform != 16))
      return corrupt_data("max transform missing or not 8 or 16 (larger transforms)");
  }
  if (header.flags2 & format::kFrame2Deblocking) {  // format 1.8
    syntax.deblocking = true;
    syntax.deblock.beta = r.u8();
    syntax.deblock.tc = r.u8();
    if (!r.ok()) return corrupt_data("deblocking parameters missing");
  }
  for (int l = 0; l < 2 && predicted; ++l) {
    const std::vector<SamplePlane>* refs = l ? reference1 : reference;
    if (!refs) continue;
    for (const SamplePlane& plane : *refs)
      if (plane.width != pw || plane.height != ph)
        return corrupt_data("reference frame size differs");
  }
  for (const auto& list : more)
    for (const SamplePlane* plane : list)
      if (plane->width != pw || plane->height != ph || plane->half_resolution != half)
        return corrupt_data("reference frame size differs");
  std::vector<SamplePlane> planes;
  MotionField x_motion;  // shared motion: the X plane's, candidate of Y and Z
  const bool cross_plane = (header.flags2 & format::kFrame2CrossPlane) != 0;
  CrossPlaneResidual x_residual;  // cross-plane prediction (1.6): X's, source of Y and Z
  const bool cross_contexts = (header.flags2 & format::kFrame2CrossPlaneContexts) != 0;
  CrossPlaneContextStates states[4];  // every plane's final context states
  for (size_t i = 0; i < plane_count; ++i) {
    const std::string name = std::string("plane ") + kPlaneNames[i];
    // Format 1.9, compact sizes: a varint before every segment but the last, which takes the
    // rest of the payload.
    const uint64_t size = !compact ? r.u32() : (i + 1 < plane_count ? r.varint() : r.remaining());
    const std::string_view bytes = r.bytes(size);
    if (!r.ok()) return corrupt_data(name + ": segment size exceeds the payload");
    PlaneCodingParams params =
        plane_params(info, static_cast<int>(i), header.flags, header.qp, syntax);
    params.end_of_plane_bin = !header.compact;  // format 1.10
    const CrossPlaneLinks links =
        plane_links(i, cross_plane, cross_contexts, temporal ? reference : nullptr, &x_residual,
                    states, p_frame ? reference : nullptr);
    MotionField motion;  // P planes: the plane's motion
    auto plane =
        bidirectional
            ? decode_b_plane(bytes, pw, ph, params, (*reference)[i], (*reference1)[i], &links)
            : decode_plane(bytes, pw, ph, params, prediction_ref ? &(*prediction_ref)[i] : nullptr,
                           shared_motion && (i == 1 || i == 2) ? &x_motion : nullptr,
                           p_frame ? &motion : nullptr, multi_ref ? &more[i] : nullptr, &links);
    if (!plane.is_ok()) return plane.status().with_context(name);
    planes.push_back(std::move(plane).value());
    planes.back().final_contexts = std::make_shared<const CrossPlaneContextStates>(states[i]);
    if (shared_motion && i == 0) x_motion = motion;
    if (p_frame)  // format 1.11: the next P frame's co-located merge candidates
      planes.back().motion = std::make_shared<const MotionField>(std::move(motion));
  }
  if (r.remaining() != 0) return corrupt_data("trailing bytes after the planes");
  for (SamplePlane& plane : planes) plane.half_resolution = half;
  return planes;
}

GeometryImage decoded_geometry(const std::vector<SamplePlane>& planes, const SequenceInfo& info,
                               int64_t frame_number, GeometryImage* into) {
  GVKIT_CHECK(planes.size() >= 3);
  GeometryImage image;
  GeometryImage& out = into ? *into : image;
  if (!planes[0].half_resolution)
    dequantize_geometry_into(planes, info, frame_number, out);
  else
    dequantize_geometry_into(upsample_planes(planes, info), info, frame_number, out);
  return out;
}

Result<GeometryImage> decode_frame_packet(std::string_view packet, const SequenceInfo& info,
                                          int64_t frame_number,
                                          const std::vector<SamplePlane>* reference,
                                          std::vector<SamplePlane>* planes_out,
                                          const std::vector<SamplePlane>* reference1,
                                          const std::vector<const std::vector<SamplePlane>*>* older,
                                          bool texture_qp_offset) {
  GVKIT_ASSIGN_OR_RETURN(
      std::vector<SamplePlane> planes,
      decode_frame_planes(packet, info, reference, reference1, older, texture_qp_offset));
  GeometryImage image = decoded_geometry(planes, info, frame_number);
  if (planes_out) *planes_out = std::move(planes);
  return image;
}

}  // namespace gvkit::codec
