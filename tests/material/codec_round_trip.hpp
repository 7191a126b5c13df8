#pragma once
// Helpers of the codec's round-trip tests (test code only, not part of the codec): the sequence
// info of a test video, sample-exact comparison of planes, and a GvidWriter -> GvidReader round
// trip that expects the decoder to reproduce the encoder's reconstructions bit for bit.

#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/codec/coding_stats.hpp"
#include "gvkit/codec/encoder_options.hpp"
#include "gvkit/codec/sequence_info.hpp"
#include "gvkit/core/geometry_image.hpp"

namespace gvkit::testing {

// make_sequence_info(frames, bit_depth, 30 fps). Contract: frames a valid video.
codec::SequenceInfo info_for(const std::vector<GeometryImage>& frames, int bit_depth = 16);

// Same size, type and bytes (two empty planes, e.g. no texture, are equal).
bool same_samples(const cv::Mat& a, const cv::Mat& b);

// Encodes `frames` with GvidWriter into a temporary file (keeping the encoder's
// reconstructions), decodes every frame with GvidReader and EXPECTs the same xyz samples and
// the frame count; returns the stream. `stats` (optional) receives the writer's frame stats.
std::string writer_round_trip(const std::vector<GeometryImage>& frames,
                              const codec::SequenceInfo& info, const codec::EncoderOptions& options,
                              std::vector<codec::FrameCodingStats>* stats = nullptr);

// Encoder configurations with P frames that a P-frame tool must survive, named: fast and slow
// preset x 0 / 1 B frames x QP 0 / 12 (intra period 5, 2 threads; index 4 is slow, no B frames,
// QP 0), then one reference, slow with shared motion, lossless and near-lossless.
std::vector<std::pair<std::string, codec::EncoderOptions>> p_frame_cases();

// The geometry PSNR (dB, peak = info's box diagonal) of every frame of `stream` decoded with
// GvidReader against `frames`, over domain pixels. Contract: a readable stream of frames.size()
// frames.
double stream_psnr_db(const std::vector<GeometryImage>& frames, const codec::SequenceInfo& info,
                      const std::string& stream);

}  // namespace gvkit::testing
