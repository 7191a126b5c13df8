#include "gvkit/codec/gvid_writer.hpp"

#include <unistd.h>

#include <algorithm>
#include <system_error>

namespace gvkit::codec {
namespace fs = std::filesystem;

namespace {

// The index entry of a packet the encoder wrote, at `offset` in the file.
format::IndexEntry index_entry(const SequenceFrame& frame, uint64_t offset) {
  const auto header = format::read_packet_header(frame.packet);
  GVKIT_CHECK(header.is_ok(), "the encoder wrote a packet header it cannot read");
  format::IndexEntry entry;
  entry.offset = offset;
  entry.frame_number = frame.number;
  entry.payload_size = header->payload_size;
  entry.header_size = static_cast<uint8_t>(header->header_size);
  entry.type = frame.type;
  return entry;
}

}  // namespace

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
  GVKIT_ASSIGN_OR_RETURN(w->encoder_, SequenceEncoder::create(info, options));
  w->out_.open(w->temp_path_, std::ios::binary | std::ios::trunc);
  if (!w->out_) return io_error(path.string() + ": cannot create " + w->temp_path_.string());
  const std::string header = format::write_file_header(info, options.resolved_profile());
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

Result<std::vector<GeometryImage>> GvidWriter::append(std::vector<SequenceFrame> coded) {
  std::vector<GeometryImage> done;
  for (SequenceFrame& f : coded) {
    out_.write(f.packet.data(), static_cast<std::streamsize>(f.packet.size()));
    if (!out_)
      return io_error(path_.string() + ": write failed at frame " + std::to_string(f.number));
    index_.push_back(index_entry(f, offset_));
    offset_ += f.packet.size();
    const size_t n = f.number;
    if (frame_bytes_.size() <= n) {
      frame_bytes_.resize(n + 1, 0);
      frame_qp_.resize(n + 1, 0);
      frame_stats_.resize(n + 1);
      frame_types_.resize(n + 1, format::FrameType::kIntra);
    }
    frame_bytes_[n] = static_cast<int64_t>(f.packet.size());
    frame_qp_[n] = f.qp;
    frame_stats_[n] = std::move(f.stats);
    frame_types_[n] = f.type;
  }
  // Display order: each reconstruction once every frame before it has been coded.
  for (SequenceFrame& f : coded) held_.emplace(f.number, std::move(f.reconstruction));
  for (auto it = held_.begin(); it != held_.end() && it->first == next_display_;
       it = held_.erase(it), ++next_display_)
    done.push_back(std::move(it->second));
  return done;
}

Result<std::vector<GeometryImage>> GvidWriter::write(const GeometryImage& frame) {
  GVKIT_CHECK(!finished_, "write after finish");
  GVKIT_ASSIGN_OR_RETURN(std::vector<SequenceFrame> coded, encoder_->push(frame));
  return append(std::move(coded));
}

Result<std::vector<GeometryImage>> GvidWriter::finish() {
  GVKIT_CHECK(!finished_, "finish twice");
  GVKIT_ASSIGN_OR_RETURN(std::vector<SequenceFrame> coded, encoder_->flush());
  GVKIT_ASSIGN_OR_RETURN(std::vector<GeometryImage> done, append(std::move(coded)));
  const std::string index = format::write_index(index_, offset_);
  out_.write(index.data(), static_cast<std::streamsize>(index.size()));
  out_.flush();
  if (!out_) return io_error(path_.string() + ": write failed (index)");
  out_.close();
  std::error_code ec;
  fs::rename(temp_path_, path_, ec);
  if (ec) return io_error(path_.string() + ": cannot rename into place: " + ec.message());
  finished_ = true;
  return done;
}

const RateController* GvidWriter::rate_controller() const { return encoder_->rate_controller(); }

const QualityController* GvidWriter::quality_controller() const {
  return encoder_->quality_controller();
}

Result<EncodedFrame> encode_sequence_frame(
    const GeometryImage& frame, const SequenceInfo& info, const EncoderOptions& options,
    uint32_t number, const std::vector<SamplePlane>& reference, RateController* rate, int* qp_used,
    const std::vector<SamplePlane>* reference1, QualityController* quality,
    const std::vector<const std::vector<SamplePlane>*>* older, ReferenceInterpolationCache* cache) {
  const bool intra = options.is_intra(number);
  GVKIT_CHECK(!intra || !reference1, "a B frame at an intra frame's position");
  const format::FrameType type =
      intra ? format::FrameType::kIntra
            : (reference1 ? format::FrameType::kBidirectional : format::FrameType::kPredicted);
  const std::vector<SamplePlane>* ref = intra ? nullptr : &reference;
  if (reference1 || intra) older = nullptr;  // several references: P frames only
  if (quality)
    return quality->encode(frame, info, options, number, ref, reference1, qp_used, older, cache);
  EncoderOptions o = options;
  if (rate) {
    o.qp = rate->next_qp(type);
    o.p_qp_offset = 0;  // the controller sets each frame type's QP itself
    o.b_qp_offset = 0;
  }
  const int offset = intra ? 0 : o.p_qp_offset + (reference1 ? o.b_qp_offset : 0);
  if (qp_used) *qp_used = o.bypass() ? 0 : std::min(51, o.qp + offset);
  for (;;) {
    GVKIT_ASSIGN_OR_RETURN(EncodedFrame encoded,
                           encode_frame(frame, info, o, number, ref, reference1, older, cache));
    if (!rate) return encoded;
    const auto bits = static_cast<int64_t>(encoded.packet.size()) * 8;
    if (!rate->overflows(bits) || o.qp >= 51) {
      rate->update(type, o.qp, bits);
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
  std::string out = format::write_file_header(info, options.resolved_profile());
  std::vector<format::IndexEntry> index;
  GVKIT_ASSIGN_OR_RETURN(std::unique_ptr<SequenceEncoder> encoder,
                         SequenceEncoder::create(info, options));
  if (frame_stats) frame_stats->assign(frames.size(), {});
  const auto append = [&](std::vector<SequenceFrame> coded) {
    for (SequenceFrame& f : coded) {
      if (frame_stats) (*frame_stats)[f.number] = std::move(f.stats);
      index.push_back(index_entry(f, out.size()));
      out += f.packet;
    }
  };
  for (const GeometryImage& frame : frames) {
    GVKIT_ASSIGN_OR_RETURN(std::vector<SequenceFrame> coded, encoder->push(frame));
    append(std::move(coded));
  }
  GVKIT_ASSIGN_OR_RETURN(std::vector<SequenceFrame> rest, encoder->flush());
  append(std::move(rest));
  out += format::write_index(index, out.size());
  return out;
}

}  // namespace gvkit::codec
