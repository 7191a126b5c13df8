#pragma once
// GvidWriter: encodes geometry images into a .gvid file: a format 2.0 stream of the profile
// options.resolved_profile() names. The stream goes to a temporary file
// beside the target ("<path>.tmp-<pid>") and is renamed over the target by finish(), so a failed
// or abandoned encode never leaves a partial .gvid behind. Packets are written in decode order
// (SequenceEncoder): with B frames a frame's packet is written once the anchor after it is.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "gvkit/codec/encoder_options.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/quality_controller.hpp"
#include "gvkit/codec/rate_controller.hpp"
#include "gvkit/codec/sequence_encoder.hpp"
#include "gvkit/codec/sequence_info.hpp"
#include "gvkit/core/geometry_image.hpp"

namespace gvkit::codec {

class GvidWriter {
 public:
  // Fails on invalid options or info (message names the option) or an unwritable path.
  static Result<std::unique_ptr<GvidWriter>> create(const std::filesystem::path& path,
                                                    const SequenceInfo& info,
                                                    const EncoderOptions& options);
  ~GvidWriter();
  GvidWriter(const GvidWriter&) = delete;
  GvidWriter& operator=(const GvidWriter&) = delete;

  // Takes the next frame (display order) and appends the packets it completes. Returns the
  // decoder's reconstructions of the frames completed, in display order, continuing where the
  // last call's ended: the frame itself without B frames; with B frames nothing while it waits
  // as a B-frame candidate, then at the next anchor the candidates and the anchor (with frame
  // threads, SequenceEncoder, a step later: each reconstruction once every frame before it in
  // display order is coded).
  Result<std::vector<GeometryImage>> write(const GeometryImage& frame);
  // Codes the frames still waiting (as P frames), writes the seek index and trailer, closes and
  // renames the file into place; returns the reconstructions of the frames it coded, in display
  // order (after those write() returned, so that every frame's reconstruction is returned once).
  Result<std::vector<GeometryImage>> finish();

  const SequenceInfo& info() const { return info_; }
  // Frames whose packets are written.
  int64_t frames_written() const { return static_cast<int64_t>(index_.size()); }
  // Per frame in display order, for the frames coded so far (a frame still waiting as a B-frame
  // candidate behind a coded one has 0 bytes, QP 0, empty stats and type kIntra until coded): the
  // size of its packet (header + payload) in bytes, its QP (0 for bypass frames: options.qp and the
  // offsets, the rate controller's, or the constant-quality search's), where its bits went per
  // plane and syntax element group, and its type.
  const std::vector<int64_t>& frame_bytes() const { return frame_bytes_; }
  int64_t header_bytes() const { return header_bytes_; }
  const std::vector<int>& frame_qp() const { return frame_qp_; }
  const std::vector<FrameCodingStats>& frame_stats() const { return frame_stats_; }
  const std::vector<format::FrameType>& frame_types() const { return frame_types_; }
  // The rate controller when options.bitrate_kbps > 0, else null.
  const RateController* rate_controller() const;
  // The constant-quality search when options.constant_quality(), else null.
  const QualityController* quality_controller() const;

 private:
  GvidWriter() = default;
  // Writes coded frames (decode order), records them; their reconstructions in display order.
  Result<std::vector<GeometryImage>> append(std::vector<SequenceFrame> coded);
  std::filesystem::path path_, temp_path_;
  std::ofstream out_;
  SequenceInfo info_;
  EncoderOptions options_;
  std::vector<format::IndexEntry> index_;
  std::unique_ptr<SequenceEncoder> encoder_;
  std::vector<int64_t> frame_bytes_;
  std::vector<int> frame_qp_;
  std::vector<FrameCodingStats> frame_stats_;
  std::vector<format::FrameType> frame_types_;
  // Reconstructions coded but not yet returned (a frame before them in display order is not
  // coded yet), by display number; the next display number to return.
  std::map<uint32_t, GeometryImage> held_;
  uint32_t next_display_ = 0;
  uint64_t offset_ = 0;
  int64_t header_bytes_ = 0;
  bool finished_ = false;
};

// Encodes frame `number` (intra or P from `reference` as options.is_intra says, or B from
// `reference` and `reference1` when reference1 is given) at options.qp and its offsets, or with
// rate control when `rate` is given, or at constant quality when `quality` is given (the QP used
// is in *qp_used). `older` (P frames with options.reference_frames() > 1): the anchors before
// `reference` since the last I frame, nearest first (encode_frame). `cache` (optional): the
// encoder's store of interpolated references, as for encode_frame.
Result<EncodedFrame> encode_sequence_frame(
    const GeometryImage& frame, const SequenceInfo& info, const EncoderOptions& options,
    uint32_t number, const std::vector<SamplePlane>& reference, RateController* rate,
    int* qp_used = nullptr, const std::vector<SamplePlane>* reference1 = nullptr,
    QualityController* quality = nullptr,
    const std::vector<const std::vector<SamplePlane>*>* older = nullptr,
    ReferenceInterpolationCache* cache = nullptr);

// Encodes a whole sequence into memory (tests, fuzz seeds, benchmarks). Returns the .gvid bytes;
// frame_stats (optional) receives each frame's bit accounting.
Result<std::string> encode_gvid(const std::vector<GeometryImage>& frames, const SequenceInfo& info,
                                const EncoderOptions& options,
                                std::vector<FrameCodingStats>* frame_stats = nullptr);

}  // namespace gvkit::codec
