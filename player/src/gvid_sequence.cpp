#include "gvkit/player/gvid_sequence.hpp"

#include <chrono>

namespace gvkit::player {

Result<std::unique_ptr<GvidSequence>> GvidSequence::open(const std::filesystem::path& path) {
  GVKIT_ASSIGN_OR_RETURN(auto reader, codec::GvidReader::open(path));
  if (reader->frame_count() == 0) return corrupt_data(path.string() + ": stream holds no frames");
  return std::unique_ptr<GvidSequence>(new GvidSequence(std::move(reader)));
}

std::string GvidSequence::name() const {
  return reader_->name() + " (.gvid, " + std::to_string(frame_count()) + " frames)";
}

double GvidSequence::fps() const { return reader_->info().fps > 0 ? reader_->info().fps : 30.0; }

Result<GeometryImage> GvidSequence::frame(int64_t index) {
  GVKIT_CHECK(index >= 0 && index < frame_count(), "frame index out of range");
  GVKIT_ASSIGN_OR_RETURN(GeometryImage image, reader_->decode_frame(index));
  image.index = index;
  image.timestamp = std::chrono::duration_cast<Timestamp>(
      std::chrono::duration<double>(static_cast<double>(index) / fps()));
  return image;
}

}  // namespace gvkit::player
