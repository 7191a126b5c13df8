#pragma once
// A FrameSource over a generator function: frame i is generator(i). This is the adapter the
// synthetic projector-camera renderer plugs into ("synthetic:"), and what tests use to feed the
// live pipeline.

#include <memory>
#include <string>

#include "gvkit/capture/frame_source.hpp"

namespace gvkit {

// Uses options.fps, paced, drop_late, pattern_cycle, cue_frames, frame_count and timeout_ms (the
// rest is ignored). With drop_late, frame i is skipped (counted as dropped, a gap in sequence) when
// its time slot passed before the consumer asked for it. Timestamps: paced, the monotonic time of
// delivery (the source behaves like a camera running at fps); unpaced with fps > 0, index / fps on
// a synthetic clock; unpaced with fps == 0, the monotonic time of delivery. sequence = index. The
// stream ends after frame_count frames (when > 0) or when the generator returns an empty image; a
// generator Status ends it with that Status (with "<name>: frame <i>: " in front). An image that is
// not one-channel CV_8U/CV_16U is a contract violation of the generator and fails the same way.
std::unique_ptr<FrameSource> make_callback_source(FrameGenerator generator,
                                                  const FrameSourceOptions& options,
                                                  std::string name = "callback");

}  // namespace gvkit
