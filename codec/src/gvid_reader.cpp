#include "gvkit/codec/gvid_reader.hpp"

#include <cstring>

#include "gvkit/core/atomic_file.hpp"

namespace gvkit::codec {

Result<std::unique_ptr<GvidReader>> GvidReader::open(const std::filesystem::path& path,
                                                     const DecoderLimits& limits) {
  GVKIT_ASSIGN_OR_RETURN(std::string bytes, read_file(path));
  return open_memory(std::move(bytes), path.string(), limits);
}

Result<std::unique_ptr<GvidReader>> GvidReader::open_memory(std::string bytes, std::string name,
                                                            const DecoderLimits& limits) {
  std::unique_ptr<GvidReader> r(new GvidReader());
  r->bytes_ = std::move(bytes);
  r->name_ = std::move(name);
  auto info = format::read_file_header(r->bytes_, &r->header_size_);
  if (!info.is_ok()) return info.status().with_context(r->name_);
  r->info_ = std::move(info).value();
  if (static_cast<int64_t>(r->info_.width) * r->info_.height > limits.max_pixels)
    return unsupported(r->name_ + ": header: " + std::to_string(r->info_.width) + "x" +
                       std::to_string(r->info_.height) + " exceeds the decoder's pixel limit");
  uint64_t index_offset = 0;
  auto index = format::read_index(r->bytes_, r->header_size_, &index_offset);
  if (index.is_ok()) {
    r->index_ = std::move(index).value();
  } else {
    r->index_rebuilt_ = true;
    r->scan_packets(r->bytes_.size());
  }
  return r;
}

// Finds packets from the end of the header on: a valid packet header (magic + CRC) whose payload
// fits is taken whole; anything else advances the search by one byte, so a damaged packet header
// loses that packet only.
void GvidReader::scan_packets(size_t end) {
  size_t pos = header_size_;
  while (pos + format::kPacketHeaderSize <= end) {
    if (std::memcmp(bytes_.data() + pos, format::kPacketMagic, 4) != 0) {
      const void* next =
          std::memchr(bytes_.data() + pos + 1, format::kPacketMagic[0], end - pos - 1);
      if (!next) break;
      pos = static_cast<size_t>(static_cast<const char*>(next) - bytes_.data());
      continue;
    }
    auto header =
        format::read_packet_header(std::string_view(bytes_).substr(pos, format::kPacketHeaderSize));
    if (header.is_ok() && header->payload_size <= end - pos - format::kPacketHeaderSize) {
      format::IndexEntry e;
      e.offset = pos;
      e.frame_number = header->frame_number;
      e.payload_size = header->payload_size;
      e.type = header->type;
      index_.push_back(e);
      pos += format::kPacketHeaderSize + header->payload_size;
    } else {
      ++pos;
    }
  }
}

Result<GeometryImage> GvidReader::decode_frame(int64_t index) {
  const std::string where = name_ + ": frame " + std::to_string(index);
  if (index < 0 || index >= frame_count())
    return invalid_argument(where + ": out of range (" + std::to_string(frame_count()) +
                            " frames)");
  if (index == cached_index_) {
    GeometryImage copy = cached_image_;
    copy.xyz_mm = cached_image_.xyz_mm.clone();
    if (!cached_image_.texture.empty()) copy.texture = cached_image_.texture.clone();
    return copy;
  }
  int64_t first = index;
  while (first > 0 && index_[static_cast<size_t>(first)].type != format::FrameType::kIntra) {
    // A P frame's reference is the packet with the previous frame number: a packet lost from
    // a rebuilt index must not silently shift the chain.
    if (index_[static_cast<size_t>(first) - 1].frame_number + 1 !=
        index_[static_cast<size_t>(first)].frame_number)
      return corrupt_data(where + ": reference frame of frame " + std::to_string(first) +
                          " is missing");
    --first;
  }
  if (index_[static_cast<size_t>(first)].type != format::FrameType::kIntra)
    return corrupt_data(where + ": no intra frame before it");
  int64_t start = first;
  if (cached_index_ >= first && cached_index_ < index) start = cached_index_ + 1;
  for (int64_t j = start; j <= index; ++j) {
    const format::IndexEntry& e = index_[static_cast<size_t>(j)];
    const std::string_view packet = std::string_view(bytes_).substr(
        e.offset,
        std::min<uint64_t>(format::kPacketHeaderSize + e.payload_size, bytes_.size() - e.offset));
    std::vector<SamplePlane> planes;
    auto frame =
        decode_frame_packet(packet, info_, j, j == first ? nullptr : &cached_planes_, &planes);
    if (!frame.is_ok()) {
      cached_index_ = -1;
      if (j == index) return frame.status().with_context(where);
      return frame.status().with_context(where + ": reference frame " + std::to_string(j));
    }
    cached_planes_ = std::move(planes);
    cached_index_ = j;
    if (j == index) {
      cached_image_ = *frame;
      cached_image_.xyz_mm = frame->xyz_mm.clone();
      return frame;
    }
  }
  return corrupt_data(where + ": not decoded");
}

int64_t GvidReader::frame_bits(int64_t index) const {
  if (index < 0 || index >= frame_count()) return 0;
  return (static_cast<int64_t>(index_[static_cast<size_t>(index)].payload_size) +
          static_cast<int64_t>(format::kPacketHeaderSize)) *
         8;
}

}  // namespace gvkit::codec
