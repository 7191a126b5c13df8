#pragma once
// GvidSequence: a .gvid geometry video as a FrameSequence, decoded by the codec's GvidReader.
// Frames are decoded on demand (a P frame from its intra frame on); a damaged frame fails alone,
// naming the file and frame, and the others stay readable.

#include <filesystem>
#include <memory>

#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/player/frame_sequence.hpp"

namespace gvkit::player {

class GvidSequence : public FrameSequence {
 public:
  // Fails naming the file when it is missing or its header cannot be read.
  static Result<std::unique_ptr<GvidSequence>> open(const std::filesystem::path& path);

  std::string name() const override;
  int64_t frame_count() const override { return reader_->frame_count(); }
  double fps() const override;
  Result<GeometryImage> frame(int64_t index) override;
  std::optional<int64_t> frame_bits(int64_t index) const override {
    return reader_->frame_bits(index);
  }

 private:
  explicit GvidSequence(std::unique_ptr<codec::GvidReader> reader) : reader_(std::move(reader)) {}
  std::unique_ptr<codec::GvidReader> reader_;
};

}  // namespace gvkit::player
