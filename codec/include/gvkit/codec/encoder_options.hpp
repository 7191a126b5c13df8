#pragma once
// Options of the .gvid encoder, bound to the flags of `gvkit encode` and to the keyword
// arguments of the Python module's encode(). The encoder writes format 2.0 streams
// (docs/bitstream.md) of the profile these options resolve to. Two kinds of fields: those a user
// picks (rate mode, preset, profile, GOP, bit depth, threads) and the per-tool switches, kept for
// experiments and set through `--tune key=value` (encoder_tune.hpp, docs/encoding.md). A tool
// switch either changes only the encoder's decisions ("encoder only") or decides whether the
// frames use a tool that 2.0 signals per frame (a packet header or payload flag); every
// combination writes a valid 2.0 stream.

#include <cstdint>
#include <string>

#include "gvkit/codec/deblocking_params.hpp"
#include "gvkit/codec/profile.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::codec {

enum class Preset {
  kFast,  // SATD-based mode decision, no 8x8 transform
  kSlow,  // rate-distortion optimised (SSD + lambda * CABAC bits) over every block type
};

const char* preset_name(Preset preset);
Result<Preset> parse_preset(const std::string& name);

// Value-domain prediction of P frames: the reference's xyz samples pass through a per-frame
// transform before motion compensation (docs/bitstream.md 2.2).
enum class ValuePrediction {
  kNone,
  kOffset,    // per plane: + offset (translation of the whole geometry)
  kWeighted,  // per plane: scale + offset (H.264's weighted prediction)
  kAffine,    // 3D affine map of the reference's (x, y, z) (head motion, scaling)
};
const char* value_prediction_name(ValuePrediction mode);
Result<ValuePrediction> parse_value_prediction(const std::string& name);

// The resolution frames are coded at (docs/bitstream.md 2.3; half_resolution.hpp).
// An I frame decides for itself and the P and B frames that predict from it.
enum class Resolution {
  kFull,  // every frame at the sequence's resolution
  kHalf,  // every lossy frame at half resolution (upsampled 2x by the decoder)
  // Per I frame: half resolution when the error of halving and upsampling the frame is at most
  // the error of coding it at full resolution (over the domain), i.e. where the detail half
  // resolution loses is below the coding noise anyway; full resolution otherwise.
  kAuto,
};
const char* resolution_name(Resolution resolution);
Result<Resolution> parse_resolution(const std::string& name);

struct EncoderOptions {
  // QP in 8-bit units, -6 (B - 8) .. 51; coded as QP' = QP + 6 (B - 8). -10 by default: the
  // coarsest QP whose decoded main-job face keeps the 95th-percentile normal error within 2
  // degrees (surface_metrics.hpp; 1.69 degrees at 2.97 bits/vertex/frame; was 12: 8.4 degrees,
  // visibly crumpled; docs/benchmarks.md, "Surface metrics"). 8- and 9-bit streams take QP 0 and
  // -6 at the least (gvkit encode then starts from those); lossless and near-lossless use none.
  int qp = -10;
  bool lossless = false;  // transform bypass: decoded samples equal the quantized input
  // The stream's profile (profile.hpp): kAuto picks it from the other options
  // (resolved_profile()). kLossless codes every frame by transform bypass (lossless, or within
  // max_error_mm when set) and kIntra every frame as an I frame, whatever lossless and the GOP
  // options say; kMain allows everything.
  Profile profile = Profile::kAuto;
  int bit_depth = 16;          // B, 8..16
  bool geometry_modes = true;  // the four geometry 4x4 intra modes
  bool intra_only = false;     // every frame intra; else an I frame every intra_period, P between
  int intra_period = 30;       // frames from one I frame to the next (1 = intra only)
  int search_range = 4;        // full-search integer motion range of P frames (samples), 0..32
  Preset preset = Preset::kSlow;
  // Near-lossless: > 0 guarantees a Euclidean point error <= max_error_mm against the input on
  // every pixel (needs a bit depth whose quantization alone stays within it); 0 = off.
  double max_error_mm = 0;
  ValuePrediction value_prediction = ValuePrediction::kNone;
  // P frames: inter macroblocks may predict the temporal difference from their neighbours.
  bool td_prediction = true;
  // P frames: motion vector precision. 0 = whole samples (frame flag bit 7 clear); 2 = half and
  // 4 = quarter samples (vectors coded in quarter samples, H.264 interpolation).
  int subpel = 4;
  // P frames: the Y and Z planes may take over the X plane's motion vector per macroblock with
  // one flag (flags2 bit 0); false: Y and Z code their own. Off by default: on the ICT face it
  // saves 4 % of the lossless rate but costs 3 % BD-rate in lossy coding (docs/benchmarks.md).
  bool shared_motion = false;
  // With shared motion: the X plane's vectors are searched on the prediction error of X, Y and Z
  // together (encoder only; always in lossless and near-lossless frames, where it pays).
  bool joint_motion_search = false;
  // Lossy P frames: inter residuals with the inter dead zone, sparse +-1 blocks dropped
  // (encoder only; the stream syntax does not change).
  bool inter_decimation = true;
  // Lossy frames: rate-distortion optimised quantization, each block's levels and last
  // coefficient chosen by SSD + lambda x estimated CABAC bits instead of a fixed rounding
  // offset (encoder only; the stream syntax does not change; docs/bitstream.md 4.2). On by
  // default: on the ICT face -4.12 % BD-rate in the fast preset at 0.94x its encode speed,
  // -5.68 % in the slow one at 0.72x (docs/benchmarks.md, RDO quantization). Lossless and
  // near-lossless streams do not use it.
  bool rdoq = true;
  // Fast preset, lossy I frames: macroblock types and modes decided by SSD + lambda x CABAC bits
  // as in the slow preset, on a shortlist (the two modes of lowest SATD-based cost per 4x4
  // block and per I16x16 macroblock; no I8x8), instead of SATD costs before any residual is
  // coded, which cannot see what the 16x16 transform saves (encoder only; the stream syntax
  // does not change). On by default: on the ICT face -18.74 % BD-rate in the fast preset at
  // 0.90x its encode speed at QP -18, on the main-job video -2.72 % (docs/benchmarks.md, "Fast
  // preset: RDO in I frames"). The slow preset decides every frame by RDO and ignores it.
  bool intra_rdo = true;
  // P frames: try the predicted vector before the motion search and, in the fast preset, take a
  // skip found there at once (encoder only: about 2x faster, slightly lower quality).
  bool skip_check = false;
  // Fast preset, lossy P frames: where TD at the searched sub-sample vector beat plain inter, TD
  // is tried again at the whole-sample search result (encoder only). Off by default: 1.04x the
  // fast encode speed at +0.08 % BD-rate on the main-job video, 1.02x at -0.05 % on the ICT face
  // (docs/benchmarks.md, "The fast preset without the whole-sample TD retry"). The slow preset,
  // lossless and near-lossless frames always try it.
  bool td_whole_retry = false;
  int plane_qp_offset[3] = {0, 0, 0};  // added to qp for X, Y, Z (lossy frames), -12..12
  // Lossy frames of a sequence with a texture plane: the texture's QP (8-bit units, 0..51) in I
  // frames, P and B frames and half resolution shifting it as they shift the frame QP (coded as
  // the texture's plane QP offset, docs/bitstream.md 2.1); -1 = the frame QP itself. 24 by
  // default: at the default geometry QP (-10) the texture would otherwise be coded near
  // losslessly, 58 % of the main job's stream (docs/benchmarks.md, "Texture QP in format 2.0").
  int texture_qp = 24;
  // Added to qp in P frames (a finer I frame is a better reference), 0..12. 4 since format 1.14
  // (was 6): -1.10 % BD-rate slow, -2.53 % fast on the ICT face (docs/benchmarks.md, format 1.14).
  int p_qp_offset = 4;
  // B frames: up to this many consecutive frames between two anchors (I or P
  // frames) are coded as B frames, predicted from the anchor before and the anchor after them
  // and coded after the latter; 0..3, or -1 = automatic: 1 in lossy streams (-17 to -19 %
  // BD-rate on the ICT face, docs/benchmarks.md), 0 in lossless and near-lossless ones (where
  // one B frame costs 3 % more rate). 0: I and P frames only.
  int bframes = -1;
  // Added to the P frames' QP in B frames (no frame predicts from a B frame), 0..12.
  int b_qp_offset = 2;
  // Rate control: > 0 sets the frame QP to meet this rate (kbit/s at the stream's fps) with a
  // buffer of buffer_seconds; qp is the starting QP. 0 = constant QP.
  double bitrate_kbps = 0;
  double buffer_seconds = 1.0;
  // Constant quality (codec/quality_controller.hpp): > 0 gives each frame the coarsest QP whose
  // reconstruction meets this geometry PSNR (dB, peak = the sequence's box diagonal) or this RMS
  // point error (mm), over domain pixels; qp is the first frame's starting QP. 0 = off; at most
  // one of the two, and neither with a bitrate, lossless or a max error.
  double target_psnr_db = 0;
  double target_rms_mm = 0;
  // Constant quality: I frames aim this many dB above the target (0..20).
  double intra_target_offset_db = 0;
  // P frames: reference frames (flags2 bit 1): each P frame predicts from up to this many of the
  // nearest anchors since the last I frame, choosing per macroblock; 1..5 (1 = one reference,
  // no flags2 bit 1), or -1 = automatic: 3 in lossy streams (ICT face, docs/benchmarks.md: -0.60 %
  // BD-rate fast, -0.18 % slow, fast encode at 0.73-1.14x one reference's speed; main-job video
  // -10.7 % fast),
  // 1 in lossless and near-lossless ones (where 2..5 cost 0.8-1.4 % more rate on the ICT face).
  int refs = -1;
  // Larger transforms (flags2 bit 2, docs/bitstream.md 4.8): 8 or 16 lets plain inter and I16x16
  // macroblocks of lossy frames code their residual with an 8x8 or 16x16 transform (chosen per
  // macroblock by rate-distortion cost); 4 = 4x4 only (no flags2 bit 2). Default 16: on the ICT
  // face -25 % BD-rate in the slow preset and -8 to -10 % in the fast one against 4, at the fast
  // preset's speed (docs/benchmarks.md). Lossless and near-lossless streams do not use it.
  int max_transform = 16;
  // Cross-plane residual prediction (flags2 bit 3, docs/bitstream.md 4.9): each Y and Z
  // macroblock may add a scaled copy (0, +-1/8 .. +-1) of the X plane's reconstructed residual
  // to its own. false writes no flags2 bit 3. On by default: on the ICT face, on top of the
  // other defaults then (refs 3, max_transform 16), it gives -0.53 % BD-rate in the fast preset
  // and -0.95 % in the slow one (-1.7 % and -2.6 % intra only; alone, on the 1.5 defaults,
  // -0.73 % / -0.90 %), -0.18 % lossless (docs/benchmarks.md, format 1.6 cross-plane section).
  bool cross_plane = true;
  // Cross-plane contexts (flags2 bit 4, docs/bitstream.md 4.10): the Y and Z planes start their
  // CABAC contexts from the X plane's final states (no new syntax). On by default: on the
  // ICT face, on top of the other defaults then, -1.90 % BD-rate in the fast preset and -2.60 % in
  // the slow one, -0.10 % lossless, at the same speed (docs/benchmarks.md, format 1.7 section).
  // (Selecting Y's and Z's contexts by X's co-located decisions as well was measured and gains
  // less: -1.71 % / -2.26 % with it, +0.22 % / +0.68 % alone.) Frames with temporal contexts
  // (below; with the defaults every P and B frame) do not use it.
  bool cross_plane_contexts = true;
  // Inter partitions (flags2 bit 5, docs/bitstream.md 4.11): in the slow preset, plain inter
  // macroblocks of P frames may split into 16x8, 8x16 or 8x8 partitions, each with its own
  // reference and vector, chosen by rate-distortion cost. The fast preset codes 16x16 only
  // (use_partitions()): no cheap decision measured paid there (ICT face: +0.4 to +0.6 % BD-rate
  // with SATD gates, -0.2 % for 25 % more CPU trying every type). On by default: on the ICT
  // face -1.17 % BD-rate in the slow preset (fast unchanged, byte for byte), -0.05 % lossless;
  // main-job video slow -2.4 % (docs/benchmarks.md, format 1.7). false, or the fast preset,
  // writes no flags2 bit 5.
  bool partitions = true;
  // Deblocking filter (flags2 bit 6, docs/bitstream.md 4.12): lossy frames filter every plane's
  // 8x8 block edges after its last macroblock (deblocking.hpp), in the loop (references are the
  // filtered planes). false writes no flags2 bit 6. Lossless
  // and near-lossless frames never use it (the max-error bound holds sample by sample).
  bool deblocking = true;
  DeblockingParams deblock;  // the filter's strength in the frame payload
  // Temporal contexts (flags2 bit 7, docs/bitstream.md 4.13): the planes of P and B frames start
  // their CABAC contexts from the states the same plane of reference 0 ended with (as AV1's
  // frame contexts), instead of from p = 0.5 or from the X plane's (cross-plane contexts, which
  // those frames then do not use): a 320x320 plane has only 400 macroblocks to learn its skip,
  // type and level statistics from. No syntax element. On by default: on the ICT face -2.49 %
  // BD-rate in the fast preset, -1.94 % in the slow one (docs/benchmarks.md, format 1.9).
  // false writes no flags2 bit 7.
  bool temporal_contexts = true;
  // Merge (payload flag bit 5, docs/bitstream.md 4.14): a skip or 16x16 inter macroblock of a P
  // frame may take the vector of one of its neighbours (left, top, top-right, top-left,
  // second-left, second-above; on reference 0) or of its co-located macroblock in reference 0
  // instead of the predictor or a coded vector, coding which of up to four in one to four bins (as
  // HEVC's merge candidates): where the motion field is smooth but not flat, a macroblock that
  // needs a neighbour's vector no longer codes a vector difference (and, without residual, a coded
  // block pattern). On by default: on the ICT face -14.04 % BD-rate in the slow preset, -2.48 %
  // in the fast one (docs/benchmarks.md, format 1.11); false writes no payload bit 5.
  bool merge = true;
  // TD16 (payload flag bit 6, docs/bitstream.md 4.15): a TD macroblock of a P frame (frame flag bit
  // 6, td_prediction) may predict the temporal difference with one I16x16 mode instead of sixteen
  // 4x4 ones, its residual then coded as a plain inter macroblock's (every transform size). On by
  // default: on the ICT face -10.20 % BD-rate in the slow preset at 0.79x its encode speed,
  // -23.24 % in the fast one at 0.90x, -7.9 % lossless (docs/benchmarks.md, format 1.12); false
  // (or td_prediction false) writes no payload bit 6.
  bool td16 = true;
  // Quadratic intra (payload flag bit 7, docs/bitstream.md 6.1): I16x16 macroblocks (of any frame)
  // not in the first macroblock row or column may predict with a least-squares quadratic surface
  // through the two rows above and the two columns left of them (quadratic_intra.hpp), and TD16
  // macroblocks likewise for their temporal difference. On by default: on the ICT face -7.20 %
  // BD-rate in the slow preset, -6.90 % in the fast one, at about the same encode speed
  // (docs/benchmarks.md, format 1.13); false writes no payload bit 7.
  bool quadratic_intra = true;
  // Half-resolution coding (packet type bit 4, docs/bitstream.md 2.3). Half-resolution frames are
  // coded 6 QP finer (a coded sample stands for four pixels: the same lambda per pixel). Lossless
  // and max-error streams are coded at full resolution. kAuto by default: on the ICT face it
  // gives -21.9 % BD-rate in the slow preset and -21.4 % in the fast one against kFull (over
  // QPs -18..24; half resolution from QP 0 on), at 0.77-0.86x the encode speed at equal QP
  // (docs/benchmarks.md, format 1.14); kFull codes every frame at full resolution.
  Resolution resolution = Resolution::kAuto;
  // Encoder only, lossy frames: in the rate-distortion decisions (SSD + lambda x bits) the
  // squared error of the domain's outline samples (inside the domain with a 4-neighbour outside
  // it or the image: the face's border and the rims of its holes, which a viewer sees as the
  // silhouette) counts this many times, so the outline is coded closer to the input than the
  // interior; the stream syntax does not change. 1 = plain SSD; 1..64. 8 by default: on the
  // main-job video (10 frames) at QP -10 / 0 the outline's Hausdorff distance drops from 0.84 to
  // 0.40 / 1.60 to 1.00 mm for +1.7 / +2.2 % rate, the normal error unchanged
  // (docs/benchmarks.md, "Surface metrics").
  int outline_weight = 8;
  // Speed decisions of the slow preset (encoder only; the stream syntax does not change;
  // docs/benchmarks.md, "Encoder speed"):
  // - rdo_shortlist: the intra modes of every 4x4, 8x8 and 16x16 block (I and temporal-difference
  //   prediction) are ranked by SATD + lambda x estimated mode bits, and only this many of the
  //   cheapest are coded by RDO; 0 = every mode (the fast preset's I frames always code 2). 0..13.
  //   3 by default: 1.57x at +0.23 % BD-rate on the main-job video, 1.48x at +0.01 % on the ICT
  //   face (2: 1.89x at +1.03 %).
  // - transform_early_exit: each candidate's residual is coded with the transform sizes from the
  //   largest down, stopping once a size leaves no level or costs more than the larger one
  //   (else every size up to max_transform is coded and the cheapest kept). Off by default: 1.20x
  //   at +1.48 % BD-rate on the main-job video (1.27x at -0.13 % on the ICT face).
  int rdo_shortlist = 3;
  bool transform_early_exit = false;
  int threads = 1;  // planes encoded in parallel (1..16); the output does not depend on it

  // Ok when every value is in range; the message names the option.
  Status check() const;
  // QP' of the X, Y, Z planes.
  int qp_prime() const { return qp + 6 * (bit_depth - 8); }
  // Whether frame `frame_number` is coded as an I frame.
  bool is_intra(int64_t frame_number) const {
    return all_intra() || frame_number % intra_period == 0;
  }
  // Whether every frame is an I frame (intra_only, intra_period 1 or profile kIntra).
  bool all_intra() const { return intra_only || intra_period <= 1 || profile == Profile::kIntra; }
  // The profile the stream is written with: profile, or with kAuto kLossless when bypass(),
  // else kIntra when all_intra(), else kMain.
  Profile resolved_profile() const;
  // Constant-quality rate control (a target PSNR or RMS error).
  bool constant_quality() const { return target_psnr_db > 0 || target_rms_mm > 0; }
  // The consecutive B frames the encoder codes: bframes, or its automatic value.
  int b_frames() const { return bframes >= 0 ? bframes : (bypass() ? 0 : 1); }
  // Whether frame `frame_number` is an anchor (I or P frame; without B frames every frame):
  // the I frames and every (b_frames() + 1)-th frame after each. The frames between two anchors
  // are B frames, but those after the last anchor of a sequence are coded as P frames.
  bool is_anchor(int64_t frame_number) const {
    const int b = b_frames();
    if (is_intra(frame_number) || b <= 0) return true;
    return frame_number % intra_period % (b + 1) == 0;
  }
  // The reference frames the encoder gives P frames: refs, or its automatic value.
  int reference_frames() const { return refs >= 1 ? refs : (bypass() ? 1 : 3); }
  // Whether lossy frames use the larger transforms.
  bool large_transforms() const { return max_transform > 4 && !bypass(); }
  // Whether P frames use inter partitions: partitions in the slow preset.
  bool use_partitions() const { return partitions && preset == Preset::kSlow; }
  // Transform-bypass coding (lossless, near-lossless, or profile kLossless).
  bool bypass() const { return lossless || max_error_mm > 0 || profile == Profile::kLossless; }
  // Whether lossy frames may be coded at half resolution.
  bool half_resolution_allowed() const { return resolution != Resolution::kFull && !bypass(); }
};

}  // namespace gvkit::codec
