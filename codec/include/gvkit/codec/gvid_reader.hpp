#pragma once
// GvidReader: random access to the frames of a .gvid stream, format 2.0 or a legacy 1.x one
// (docs/bitstream.md, appendix A). The whole file is read and checked on open; the seek index at
// the end is used when it is intact, otherwise the packets are found by a scan (index_rebuilt()).
// Decoding a damaged packet, or one that breaks the rules of the stream's format and profile,
// fails for that frame only, with a Status naming the file, the frame and the field ("x.gvid:
// frame 3: profile intra: a P frame (I frames only)"); other frames still decode.

#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "gvkit/codec/frame_coding.hpp"
#include "gvkit/codec/gvid_format.hpp"
#include "gvkit/codec/sequence_info.hpp"
#include "gvkit/core/geometry_image.hpp"

namespace gvkit::codec {

class GvidReader {
 public:
  // Fails naming the file when it is missing, not a .gvid stream, of an unsupported version, or
  // its header is damaged (a damaged header makes every frame unusable).
  static Result<std::unique_ptr<GvidReader>> open(const std::filesystem::path& path,
                                                  const DecoderLimits& limits = {});
  // The same over bytes already in memory; name is used in messages.
  static Result<std::unique_ptr<GvidReader>> open_memory(std::string bytes, std::string name,
                                                         const DecoderLimits& limits = {});

  const SequenceInfo& info() const { return info_; }
  // The stream's version and profile (format.legacy() for a 1.x stream).
  const format::StreamFormat& format() const { return format_; }
  int64_t frame_count() const { return static_cast<int64_t>(index_.size()); }
  // Decodes frame `index` (0-based, display order; the packets are in decode order). A P frame
  // needs the anchors (I and P frames) from the previous intra frame on, a B frame also the
  // anchor after it; the last few decoded anchors are kept, so that reading in display order
  // decodes each frame once. A P frame with several references (format 1.6) gets the up to 5
  // nearest anchors since the previous intra frame. A damaged frame fails this frame and the frames
  // that depend on it (the P frames after it up to the next intra frame, the B frames around them),
  // whose messages name it ("frame 3: reference frame 4: payload CRC mismatch"). The image's
  // pixel buffers are those of the image returned before when its caller has released every
  // header of it (no new pages per frame); an image still held is never written over.
  Result<GeometryImage> decode_frame(int64_t index);
  // Bits of the frame's packet (header + payload); 0 for an index out of range.
  int64_t frame_bits(int64_t index) const;
  // The packet header of frame `index` (display order; contract: 0 <= index < frame_count());
  // fails when it is damaged.
  Result<format::PacketHeader> packet_header(int64_t index) const;
  // Type of frame `index` (display order; contract: 0 <= index < frame_count()).
  format::FrameType frame_type(int64_t index) const { return entry(index).type; }
  // Reference frames of frame `index` (packet_reference_count; -1 when its packet is damaged).
  int frame_references(int64_t index) const;
  // Position of frame `index` (display order) in the stream's decode order.
  int64_t decode_position(int64_t index) const { return static_cast<int64_t>(order_.at(index)); }
  // True when the seek index was missing or damaged and the packets were found by a scan.
  bool index_rebuilt() const { return index_rebuilt_; }
  int64_t file_bytes() const { return static_cast<int64_t>(bytes_.size()); }
  int64_t header_bytes() const { return static_cast<int64_t>(header_size_); }
  const std::string& name() const { return name_; }

 private:
  GvidReader() = default;
  void scan_packets(size_t end);
  // Sorts the packets into display order (order_).
  void sort_display_order();
  const format::IndexEntry& entry(int64_t index) const {
    return index_[order_.at(static_cast<size_t>(index))];
  }
  bool is_anchor(int64_t index) const {
    return entry(index).type != format::FrameType::kBidirectional;
  }
  // A decoded frame's planes (as coded: at half resolution when the packet says so); its
  // geometry image is made from them when the frame is asked for (decoded_geometry), so that a
  // frame decoded only as a reference costs no image and a returned image needs no copy.
  struct Decoded {
    int64_t index = -1;  // display order
    std::vector<SamplePlane> planes;
  };
  // The decoded anchor `index` (I or P frame) and the chain of anchors it needs; `where` names
  // frame `requested` (the one asked for) in messages, which name any other failing frame as a
  // reference frame.
  Result<std::shared_ptr<const Decoded>> decode_anchor(int64_t index, int64_t requested,
                                                       const std::string& where);
  // The anchor before (direction -1) or after (+1) frame `index`, or -1; fails when a frame
  // between them is missing (a packet lost from a rebuilt index).
  Result<int64_t> neighbour_anchor(int64_t index, int direction, const std::string& where) const;
  // `older` (P frames): the anchors before ref0 since the last intra frame, nearest first.
  Result<std::vector<SamplePlane>> decode_packet(
      int64_t index, const Decoded* ref0, const Decoded* ref1,
      const std::vector<const Decoded*>& older = {}) const;

  // The geometry image of `planes` (frame `index`), in the buffers of the last one returned when
  // its user has let them go (no other header shares them), else in new ones.
  GeometryImage output_image(const std::vector<SamplePlane>& planes, int64_t index);

  std::string bytes_, name_;
  GeometryImage output_;  // headers of the last returned image's buffers
  SequenceInfo info_;
  format::StreamFormat format_;
  size_t header_size_ = 0;
  std::vector<format::IndexEntry> index_;  // decode order
  std::vector<size_t> order_;              // display order -> position in index_
  bool index_rebuilt_ = false;
  // The anchors decoded last (at most kCachedAnchors, oldest first: the 5 references of a P
  // frame, the anchor itself and the one after a B frame) and the last B frame.
  static constexpr size_t kCachedAnchors = format::kMaxReferenceFrames + 2;
  std::deque<std::shared_ptr<const Decoded>> anchors_;
  std::shared_ptr<const Decoded> last_b_;
};

}  // namespace gvkit::codec
