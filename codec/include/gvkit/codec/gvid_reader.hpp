#pragma once
// GvidReader: random access to the frames of a .gvid stream. The whole file is read and checked
// on open; the seek index at the end is used when it is intact, otherwise the packets are found
// by a scan (index_rebuilt()). Decoding a damaged packet fails for that frame only, with a Status
// naming the file, the frame and the field; other frames still decode.

#include <cstdint>
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
  int64_t frame_count() const { return static_cast<int64_t>(index_.size()); }
  // Decodes frame `index` (0-based): a P frame is decoded from the previous intra frame on
  // (reusing the last decoded frame when it lies on that chain, so sequential reading decodes
  // each frame once). A damaged frame fails this frame and the P frames after it up to the next
  // intra frame.
  Result<GeometryImage> decode_frame(int64_t index);
  // Bits of the frame's packet (header + payload); 0 for an index out of range.
  int64_t frame_bits(int64_t index) const;
  format::FrameType frame_type(int64_t index) const { return index_.at(index).type; }
  // True when the seek index was missing or damaged and the packets were found by a scan.
  bool index_rebuilt() const { return index_rebuilt_; }
  int64_t file_bytes() const { return static_cast<int64_t>(bytes_.size()); }
  int64_t header_bytes() const { return static_cast<int64_t>(header_size_); }
  const std::string& name() const { return name_; }

 private:
  GvidReader() = default;
  void scan_packets(size_t end);

  std::string bytes_, name_;
  SequenceInfo info_;
  size_t header_size_ = 0;
  std::vector<format::IndexEntry> index_;
  bool index_rebuilt_ = false;
  // The last frame decoded and its planes: the reference for decoding the next P frame.
  int64_t cached_index_ = -1;
  std::vector<SamplePlane> cached_planes_;
  GeometryImage cached_image_;
};

}  // namespace gvkit::codec
