#pragma once
// FrameSequence: a geometry video as the player sees it, whatever stores it. Frames are
// GeometryImages addressed by index 0..frame_count()-1; a frame that fails to load is a failed
// Result naming the frame, and the other frames stay readable.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::player {

class FrameSequence {
 public:
  virtual ~FrameSequence() = default;

  // Opens a sequence by looking at the path:
  //   a folder of frame_NNNNNN.exr GeometryImages (X, Y, Z, [T], M), or of RangeScan EXRs
  //   (X, Y, Z, T, Q, M, as `gvkit reconstruct` writes them: the camera grid is the image,
  //   `valid` the mask); or a .gvid stream (decoded by the codec).
  // Fails naming the path when it is missing, holds no frames, or is of an unknown kind.
  static Result<std::unique_ptr<FrameSequence>> create(const std::filesystem::path& path);

  // Short description for titles and messages, e.g. "take3 (EXR folder, 120 frames)".
  virtual std::string name() const = 0;
  virtual int64_t frame_count() const = 0;
  // Nominal frames per second (> 0).
  virtual double fps() const = 0;
  // Loads frame `index` (0 <= index < frame_count(), contract). The image's index is set and
  // its timestamp is the frame's presentation time from the start of the sequence. Not
  // thread-safe: one thread at a time (stream decoders keep reference-frame state).
  virtual Result<GeometryImage> frame(int64_t index) = 0;
  // Size of the frame in the stream (bits), when the container knows it.
  virtual std::optional<int64_t> frame_bits(int64_t index) const { return std::nullopt; }
};

}  // namespace gvkit::player
