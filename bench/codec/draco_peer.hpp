#pragma once
// Draco per frame as a rate-distortion peer of the .gvid codec (bench only: draco::draco is a
// benchmark dependency, never one of the codec library). Each geometry image's domain pixels
// become a triangle mesh (the player's grid triangulation, gvkit/player/geometry_image_mesh.hpp)
// or a point cloud, Draco encodes it with quantized positions and decodes it, and the decoded
// points (which Draco reorders) are matched back to the pixels by nearest point, so the codec's
// own metrics (gvkit/codec/geometry_metrics.hpp) apply unchanged.

#include <cstdint>

#include "gvkit/codec/sequence_info.hpp"
#include "gvkit/core/geometry_image.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::bench {

enum class DracoGeometry {
  kMesh,        // grid triangulation, edgebreaker connectivity, parallelogram prediction
  kPointCloud,  // positions only, kd-tree coding (no connectivity: ours is implicit in the grid)
};
const char* draco_geometry_name(DracoGeometry geometry);

struct DracoOptions {
  DracoGeometry geometry = DracoGeometry::kMesh;
  int quantization_bits = 16;  // position quantization, 1..30 (the range: 11..16)
  int compression_level = 7;   // 0..10, Draco's -cl: speed 10 - level (7 = draco_encoder's default)
  // Quantize in the sequence's box (SequenceInfo::box_min_mm, largest extent): the same grid as
  // .gvid samples of the same bit depth. False: Draco's default, each frame's own bounding box.
  bool sequence_box = true;
  // Ok when every value is in range; the message names the option.
  Status check() const;
};

struct DracoFrameResult {
  GeometryImage decoded;     // the frame with each domain pixel's xyz = the nearest decoded point
  int64_t bytes = 0;         // Draco's encoded buffer
  int64_t input_points = 0;  // vertices given to Draco (domain pixels with finite xyz)
  int64_t decoded_points = 0;
  double encode_seconds = 0;  // process CPU time of Draco's encode call alone
  double decode_seconds = 0;  // process CPU time of Draco's decode call alone
};

// Encodes and decodes one frame. frame must pass frame.check() and lie in info's box (contract:
// info is the frame's sequence). Fails on invalid options (naming the option) or when Draco
// fails (with Draco's message).
Result<DracoFrameResult> draco_round_trip(const GeometryImage& frame,
                                          const codec::SequenceInfo& info,
                                          const DracoOptions& options);

}  // namespace gvkit::bench
