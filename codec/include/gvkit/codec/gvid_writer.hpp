#pragma once
// GvidWriter: encodes geometry images into a .gvid file. The stream goes to a temporary file
// beside the target ("<path>.tmp-<pid>") and is renamed over the target by finish(), so a failed
// or abandoned encode never leaves a partial .gvid behind.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "gvkit/codec/encoder_options.hpp"
#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/quality_controller.hpp"
#include "gvkit/codec/rate_controller.hpp"
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

  // Encodes and appends one frame; returns the decoder's reconstruction of it.
  Result<GeometryImage> write(const GeometryImage& frame);
  // Writes the seek index and trailer, closes and renames the file into place.
  Status finish();

  const SequenceInfo& info() const { return info_; }
  int64_t frames_written() const { return static_cast<int64_t>(index_.size()); }
  // Size of each frame's packet (header + payload) in bytes.
  const std::vector<int64_t>& frame_bytes() const { return frame_bytes_; }
  int64_t header_bytes() const { return header_bytes_; }
  // QP of each frame written (0 for bypass frames): options.qp (+ p_qp_offset in P frames), the
  // rate controller's, or the constant-quality search's.
  const std::vector<int>& frame_qp() const { return frame_qp_; }
  // Where each frame's bits went, per plane and syntax element group.
  const std::vector<FrameCodingStats>& frame_stats() const { return frame_stats_; }
  // The rate controller when options.bitrate_kbps > 0, else null.
  const RateController* rate_controller() const { return rate_.get(); }
  // The constant-quality search when options.constant_quality(), else null.
  const QualityController* quality_controller() const { return quality_.get(); }

 private:
  GvidWriter() = default;
  std::filesystem::path path_, temp_path_;
  std::ofstream out_;
  SequenceInfo info_;
  EncoderOptions options_;
  std::vector<format::IndexEntry> index_;
  std::vector<SamplePlane> reference_;  // reconstruction of the last frame written
  std::vector<int64_t> frame_bytes_;
  std::vector<int> frame_qp_;
  std::vector<FrameCodingStats> frame_stats_;
  std::unique_ptr<RateController> rate_;
  std::unique_ptr<QualityController> quality_;
  uint64_t offset_ = 0;
  int64_t header_bytes_ = 0;
  bool finished_ = false;
};

// Encodes frame `number` (intra or P from `reference` as options.is_intra says) at options.qp, or
// with rate control when `rate` is given, or at constant quality when `quality` is given (the
// QP used is in *qp_used).
Result<EncodedFrame> encode_sequence_frame(const GeometryImage& frame, const SequenceInfo& info,
                                           const EncoderOptions& options, uint32_t number,
                                           const std::vector<SamplePlane>& reference,
                                           RateController* rate, int* qp_used = nullptr,
                                           QualityController* quality = nullptr);

// Encodes a whole sequence into memory (tests, fuzz seeds, benchmarks). Returns the .gvid bytes;
// frame_stats (optional) receives each frame's bit accounting.
Result<std::string> encode_gvid(const std::vector<GeometryImage>& frames, const SequenceInfo& info,
                                const EncoderOptions& options,
                                std::vector<FrameCodingStats>* frame_stats = nullptr);

}  // namespace gvkit::codec
