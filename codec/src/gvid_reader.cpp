#include "gvkit/codec/gvid_reader.hpp"

#include <algorithm>
#include <atomic>

#include "gvkit/codec/crc32.hpp"
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
  auto info = format::read_file_header(r->bytes_, &r->header_size_, &r->format_);
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
  r->sort_display_order();
  return r;
}

// Finds packets from the end of the header on: a valid packet header (magic + CRC) whose payload
// fits is taken whole; anything else advances the search by one byte, so a damaged packet header
// loses that packet only. A compact header (format 1.10) has only a CRC-8 behind its 2-byte
// magic, so it counts as a packet only when its payload's CRC-32 matches too or when it ends
// where something a stream holds begins (another valid packet header, the index, the end): a
// compact packet with a damaged payload is still found, and its frame reports the damage.
void GvidReader::scan_packets(size_t end) {
  const auto boundary_at = [&](size_t at) {
    if (at == end) return true;
    const std::string_view next = std::string_view(bytes_).substr(at, end - at);
    return (next.size() >= 4 && next.substr(0, 4) == std::string_view(format::kIndexMagic, 4)) ||
           format::read_packet_header(next).is_ok();
  };
  size_t pos = header_size_;
  while (pos + format::kCompactPacketHeaderMinSize <= end) {
    const std::string_view rest = std::string_view(bytes_).substr(pos, end - pos);
    if (!format::starts_with_packet_magic(rest)) {
      ++pos;
      continue;
    }
    auto header = format::read_packet_header(rest);
    bool found = header.is_ok() && header->payload_size <= rest.size() - header->header_size;
    if (found && header->compact)
      found =
          crc32(rest.substr(header->header_size, header->payload_size)) == header->payload_crc ||
          boundary_at(pos + header->header_size + header->payload_size);
    if (found) {
      format::IndexEntry e;
      e.offset = pos;
      e.frame_number = header->frame_number;
      e.payload_size = header->payload_size;
      e.header_size = static_cast<uint8_t>(header->header_size);
      e.type = header->type;
      index_.push_back(e);
      pos += e.packet_size();
    } else {
      ++pos;
    }
  }
}

void GvidReader::sort_display_order() {
  order_.resize(index_.size());
  for (size_t i = 0; i < order_.size(); ++i) order_[i] = i;
  std::stable_sort(order_.begin(), order_.end(), [&](size_t a, size_t b) {
    return index_[a].frame_number < index_[b].frame_number;
  });
}

Result<int64_t> GvidReader::neighbour_anchor(int64_t index, int direction,
                                             const std::string& where) const {
  for (int64_t j = index + direction; j >= 0 && j < frame_count(); j += direction) {
    // The frames between a frame and its anchor have consecutive frame numbers: a packet lost
    // from a rebuilt index must not silently shift the references.
    const int64_t a = std::min(j, j - direction), b = std::max(j, j - direction);
    if (entry(a).frame_number + 1 != entry(b).frame_number)
      return corrupt_data(where + ": reference frame of frame " + std::to_string(index) +
                          " is missing");
    if (is_anchor(j)) return j;
  }
  return int64_t{-1};
}

Result<std::vector<SamplePlane>> GvidReader::decode_packet(
    int64_t index, const Decoded* ref0, const Decoded* ref1,
    const std::vector<const Decoded*>& older) const {
  std::vector<const std::vector<SamplePlane>*> older_planes;
  for (const Decoded* d : older) older_planes.push_back(&d->planes);
  const format::IndexEntry& e = entry(index);
  const std::string_view packet = std::string_view(bytes_).substr(
      e.offset, std::min<uint64_t>(e.packet_size(), bytes_.size() - e.offset));
  // The rules of a 2.0 stream's format and profile; damage is decode_frame_packet's to report
  // (the payload's flags are checked once its CRC matches).
  if (auto header = format::read_packet_header(packet); header.is_ok()) {
    std::string_view payload = packet.substr(std::min<size_t>(header->header_size, packet.size()));
    if (payload.size() < header->payload_size ||
        crc32(payload.data(), header->payload_size) != header->payload_crc)
      payload = {};
    else
      payload = payload.substr(0, header->payload_size);
    GVKIT_RETURN_IF_ERROR(format::check_packet_conformance(format_, *header, payload));
  }
  return decode_frame_planes(packet, info_, ref0 ? &ref0->planes : nullptr,
                             ref1 ? &ref1->planes : nullptr,
                             older_planes.empty() ? nullptr : &older_planes, format_.major >= 2);
}

Result<std::shared_ptr<const GvidReader::Decoded>> GvidReader::decode_anchor(
    int64_t index, int64_t requested, const std::string& where) {
  const auto cached = [&](int64_t j) -> std::shared_ptr<const Decoded> {
    for (const auto& d : anchors_)
      if (d->index == j) return d;
    return nullptr;
  };
  // Back along the anchors (newest first) until every anchor to decode has its references in
  // the chain: one anchor before a P frame, up to kMaxReferenceFrames before one with several
  // references (flags2 bit 1), never past an intra frame. With one reference per P frame the
  // chain stops at the first decoded anchor.
  const auto references_of = [&](int64_t j) {
    const format::IndexEntry& e = entry(j);
    if (e.type == format::FrameType::kIntra) return 0;
    auto header =
        format::read_packet_header(std::string_view(bytes_).substr(e.offset, e.header_size));
    return header.is_ok() && (header->flags2 & format::kFrame2MultiRef)
               ? format::kMaxReferenceFrames
               : 1;
  };
  std::vector<int64_t> chain;
  std::vector<std::shared_ptr<const Decoded>> held;  // per chain entry: decoded, or null
  int reach = 0;  // anchors further back that the chain's frames to decode still need
  for (int64_t j = index;;) {
    chain.push_back(j);
    held.push_back(cached(j));
    if (!held.back()) reach = std::max(reach, references_of(j));
    if (reach == 0 || entry(j).type == format::FrameType::kIntra) break;
    GVKIT_ASSIGN_OR_RETURN(const int64_t before, neighbour_anchor(j, -1, where));
    if (before < 0) return corrupt_data(where + ": no intra frame before it");
    j = before;
    --reach;
  }
  for (size_t q = chain.size(); q-- > 0;) {
    if (held[q]) continue;
    const int64_t j = chain[q];
    auto d = std::make_shared<Decoded>();
    d->index = j;
    const bool intra = entry(j).type == format::FrameType::kIntra;
    // References: the anchors before it in the chain (held, decoded or just decoded).
    std::vector<const Decoded*> older;
    for (size_t r = q + 2; !intra && r < chain.size() && r <= q + format::kMaxReferenceFrames;
         ++r) {
      if (!held[r]) break;
      older.push_back(held[r].get());
    }
    const Decoded* ref0 = !intra && q + 1 < chain.size() ? held[q + 1].get() : nullptr;
    if (!intra && !ref0) return corrupt_data(where + ": no intra frame before it");
    auto planes = decode_packet(j, ref0, nullptr, older);
    if (!planes.is_ok()) {
      if (j == requested) return planes.status().with_context(where);
      return planes.status().with_context(where + ": reference frame " + std::to_string(j));
    }
    d->planes = std::move(planes).value();
    anchors_.push_back(d);
    if (anchors_.size() > kCachedAnchors) anchors_.pop_front();
    held[q] = std::move(d);
  }
  return held.front();
}

Result<GeometryImage> GvidReader::decode_frame(int64_t index) {
  const std::string where = name_ + ": frame " + std::to_string(index);
  if (index < 0 || index >= frame_count())
    return invalid_argument(where + ": out of range (" + std::to_string(frame_count()) +
                            " frames)");
  if (is_anchor(index)) {
    GVKIT_ASSIGN_OR_RETURN(const std::shared_ptr<const Decoded> d,
                           decode_anchor(index, index, where));
    return output_image(d->planes, index);
  }
  if (last_b_ && last_b_->index == index) return output_image(last_b_->planes, index);
  GVKIT_ASSIGN_OR_RETURN(const int64_t before, neighbour_anchor(index, -1, where));
  GVKIT_ASSIGN_OR_RETURN(const int64_t after, neighbour_anchor(index, 1, where));
  if (before < 0) return corrupt_data(where + ": B frame without an anchor frame before it");
  if (after < 0) return corrupt_data(where + ": B frame without an anchor frame after it");
  // The later anchor first: decoding it from the earlier one keeps both in the cache.
  GVKIT_ASSIGN_OR_RETURN(const std::shared_ptr<const Decoded> ref1,
                         decode_anchor(after, index, where));
  GVKIT_ASSIGN_OR_RETURN(const std::shared_ptr<const Decoded> ref0,
                         decode_anchor(before, index, where));
  auto d = std::make_shared<Decoded>();
  d->index = index;
  auto planes = decode_packet(index, ref0.get(), ref1.get());
  if (!planes.is_ok()) return planes.status().with_context(where);
  d->planes = std::move(planes).value();
  last_b_ = d;
  return output_image(d->planes, index);
}

GeometryImage GvidReader::output_image(const std::vector<SamplePlane>& planes, int64_t index) {
  // (Read atomically: a caller may release its header on another thread meanwhile, which
  // OpenCV counts with an atomic decrement.)
  const auto alone = [](const cv::Mat& m) {
    return !m.u || std::atomic_ref<int>(m.u->refcount).load() == 1;
  };
  if (!alone(output_.xyz_mm) || !alone(output_.texture)) output_ = GeometryImage();
  return decoded_geometry(planes, info_, index, &output_);
}

int GvidReader::frame_references(int64_t index) const {
  const format::IndexEntry& e = entry(index);
  auto refs = packet_reference_count(std::string_view(bytes_).substr(
      e.offset, std::min<uint64_t>(e.packet_size(), bytes_.size() - e.offset)));
  return refs.is_ok() ? *refs : -1;
}

Result<format::PacketHeader> GvidReader::packet_header(int64_t index) const {
  return format::read_packet_header(std::string_view(bytes_).substr(entry(index).offset));
}

int64_t GvidReader::frame_bits(int64_t index) const {
  if (index < 0 || index >= frame_count()) return 0;
  return static_cast<int64_t>(entry(index).packet_size()) * 8;
}

}  // namespace gvkit::codec
