#include "gvkit/codec/gvid_writer.hpp"

#include <unistd.h>

#include <algorithm>
#include <system_error>

namespace gvkit::codec {
namespace fs = std::filesystem;

Result<std::unique_ptr<GvidWriter>> GvidWriter::create(const fs::path& path,
                                                       const SequenceInfo& info,
                                                       const EncoderOptions& options) {
  GVKIT_RETURN_IF_ERROR(options.check());
  GVKIT_RETURN_IF_ERROR(info.check());
  if (info.bit_depth != options.bit_depth)
    return invalid_argument("bit depth of the sequence (" + std::to_string(info.bit_depth) +
                            ") differs from the options' (" + std::to_string(options.bit_depth) +
                            ")");
  std::unique_ptr<GvidWriter> w(new GvidWriter());
  w->path_ = path;
  w->temp_path_ = path;
  w->temp_path_ += ".tmp-" + std::to_string(::getpid());
  w->info_ = info;
  w->options_ = options;
  if (near_lossless_delta(info, options.max_error_mm) < 0)
    return invalid_argument("max error " + std::to_string(options.max_error_mm) +
                            " mm is below the quantization error at " +
                            std::to_string(info.bit_depth) + " bits; raise the bit depth");
  if (options.bitrate_kbps > 0) w->rate_ = std::make_unique<RateController>(options, info.fps);
  if (options.constant_quality()) {
    GVKIT_ASSIGN_OR_RETURN(w->quality_, QualityController::create(options, info));
  }
  w->out_.open(w->temp_path_, std::ios::binary | std::ios::trunc);
  if (!w->out_) return io_error(path.string() + ": cannot create " + w->temp_path_.string());
  const std::string header = format::write_file_header(info);
  w->out_.write(header.data(), static_cast<std::streamsize>(header.size()));
  w->offset_ = header.size();
  w->header_bytes_ = static_cast<int64_t>(header.size());
  if (!w->out_) return io_error(path.string() + ": write failed");
  return w;
}

GvidWriter::~GvidWriter() {
  if (!finished_) {
    out_.close();
    std::error_code ec;
    fs::remove(temp_path_, ec);
  }
}

Result<GeometryImage> GvidWriter::write(const GeometryImage& frame) {
  GVKIT_CHECK(!finished_, "write after finish");
  const auto number = static_cast<uint32_t>(index_.size());
  const bool intra = options_.is_intra(number);
  int qp = 0;
  GVKIT_ASSIGN_OR_RETURN(EncodedFrame encoded,
                         encode_sequence_frame(frame, info_, options_, number, reference_,
                                               rate_.get(), &qp, quality_.get()));
  frame_qp_.push_back(qp);
  frame_stats_.push_back({intra, encoded.plane_stats});
  reference_ = std::move(encoded.planes);
  out_.write(encoded.packet.data(), static_cast<std::streamsize>(encoded.packet.size()));
  if (!out_) return io_error(path_.string() + ": write failed at frame " + std::to_string(number));
  format::IndexEntry entry;
  entry.offset = offset_;
  entry.frame_number = number;
  entry.payload_size = static_cast<uint32_t>(encoded.packet.size() - format::kPacketHeaderSize);
  entry.type = intra ? format::FrameType::kIntra : format::FrameType::kPredicted;
  index_.push_back(entry);
  frame_bytes_.push_back(static_cast<int64_t>(encoded.packet.size()));
  offset_ += encoded.packet.size();
  return std::move(encoded.reconstruction);
}

Status GvidWriter::finish() {
  GVKIT_CHECK(!finished_, "finish twice");
  const std::string index = format::write_index(index_, offset_);
  out_.write(index.data(), static_cast<std::streamsize>(index.size()));
  out_.flush();
  if (!out_) return io_error(path_.string() + ": write failed (index)");
  out_.close();
  std::error_code ec;
  fs::rename(temp_path_, path_, ec);
  if (ec) return io_error(path_.string() + ": cannot rename into place: " + ec.message());
  finished_ = true;
  return Status::ok();
}

Result<EncodedFrame> encode_sequence_frame(const GeometryImage& frame, const SequenceInfo& info,
                                           const EncoderOptions& options, uint32_t number,
                                           const std::vector<SamplePlane>& reference,
                                           RateController* rate, int* qp_used,
                                           QualityController* quality) {
  const bool intra = options.is_intra(number);
  const std::vector<SamplePlane>* ref = intra ? nullptr : &reference;
  if (quality) return quality->encode(frame, info, options, number, ref, qp_used);
  EncoderOptions o = options;
  if (rate) {
    o.qp = rate->next_qp(intra);
    o.p_qp_offset = 0;  // the controller sets each frame type's QP itself
  }
  if (qp_used) *qp_used = o.bypass() ? 0 : std::min(51, o.qp + (intra ? 0 : o.p_qp_offset));
  for (;;) {
    GVKIT_ASSIGN_OR_RETURN(EncodedFrame encoded, encode_frame(frame, info, o, number, ref));
    if (!rate) return encoded;
    const auto bits = static_cast<int64_t>(encoded.packet.size()) * 8;
    if (!rate->overflows(bits) || o.qp >= 51) {
      rate->update(intra, o.qp, bits);
      if (qp_used) *qp_used = o.qp;
      return encoded;
    }
    o.qp = std::min(51, o.qp + 3);  // would overflow the buffer: coarser
  }
}

Result<std::string> encode_gvid(const std::vector<GeometryImage>& frames, const SequenceInfo& info,
                                const EncoderOptions& options,
                                std::vector<FrameCodingStats>* frame_stats) {
  GVKIT_RETURN_IF_ERROR(options.check());
  GVKIT_RETURN_IF_ERROR(info.check());
  std::string out = format::write_file_header(info);
  std::vector<format::IndexEntry> index;
  std::vector<SamplePlane> reference;
  std::unique_ptr<RateController> rate;
  if (options.bitrate_kbps > 0) rate = std::make_unique<RateController>(options, info.fps);
  std::unique_ptr<QualityController> quality;
  if (options.constant_quality()) {
    GVKIT_ASSIGN_OR_RETURN(quality, QualityController::create(options, info));
  }
  for (size_t i = 0; i < frames.size(); ++i) {
    const bool intra = options.is_intra(static_cast<int64_t>(i));
    GVKIT_ASSIGN_OR_RETURN(EncodedFrame encoded,
                           encode_sequence_frame(frames[i], info, options, static_cast<uint32_t>(i),
                                                 reference, rate.get(), nullptr, quality.get()));
    reference = std::move(encoded.planes);
    if (frame_stats) frame_stats->push_back({intra, encoded.plane_stats});
    format::IndexEntry entry;
    entry.type = intra ? format::FrameType::kIntra : format::FrameType::kPredicted;
    entry.offset = out.size();
    entry.frame_number = static_cast<uint32_t>(i);
    entry.payload_size = static_cast<uint32_t>(encoded.packet.size() - format::kPacketHeaderSize);
    index.push_back(entry);
    out += encoded.packet;
  }
  out += format::write_index(index, out.size());
  return out;
}

}  // namespace gvkit::codec
