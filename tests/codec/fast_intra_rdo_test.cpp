// The fast preset's RDO in I frames (EncoderOptions::intra_rdo, encoder only): the decoder
// reproduces the encoder bit for bit, a shortlist as long as the mode list is the full RDO, the
// fast preset's intra-only streams cost less at the same quality, and the slow preset,
// lossless and near-lossless streams do not change.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "codec_round_trip.hpp"
#include "geometry_video_material.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/geometry_planes.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "gvkit/codec/intra_prediction.hpp"
#include "gvkit/codec/plane_coding.hpp"

namespace gvkit::codec {
namespace {

TEST(FastIntraRdo, DecoderReproducesTheEncoderBitExactly) {
  const auto frames = testing::make_moving_analytic_video(48, 6);
  const SequenceInfo info = testing::info_for(frames);
  for (const int qp : {-6, 18}) {
    SCOPED_TRACE("qp " + std::to_string(qp));
    EncoderOptions o;
    o.qp = qp;
    o.preset = Preset::kFast;
    o.intra_period = 4;  // I P B P, I P
    o.threads = 2;
    ASSERT_TRUE(o.intra_rdo);  // on by default
    testing::writer_round_trip(frames, info, o);
  }
}

// The X plane of a frame as the encoder codes it (16-bit samples, padded to whole macroblocks).
SamplePlane x_plane(int size) {
  const auto frames = testing::make_moving_analytic_video(size, 1);
  return quantize_geometry(frames[0], testing::info_for(frames)).at(0);
}

TEST(FastIntraRdo, AShortlistOfEveryModeIsTheFullRdo) {
  const SamplePlane plane = x_plane(48);
  PlaneCodingParams p;
  p.qp_prime = 60;
  p.max_transform = 16;
  p.rdo = true;
  const std::string full = encode_plane(plane, p).bytes;
  p.intra_rdo_shortlist = kIntra4x4ModeCount;
  EXPECT_EQ(encode_plane(plane, p).bytes, full);
  p.intra_rdo_shortlist = 1;
  EXPECT_NE(encode_plane(plane, p).bytes, full);  // the option reaches the decisions
}

// Bits and PSNR (dB) of a stream against its source.
struct Rate {
  size_t bytes = 0;
  double psnr_db = 0;
};
Rate rate(const std::string& stream, const std::vector<GeometryImage>& frames,
          const SequenceInfo& info) {
  auto reader = GvidReader::open_memory(stream, "x.gvid").value();
  GeometryError total;
  for (int64_t f = 0; f < reader->frame_count(); ++f)
    accumulate(total, geometry_error(frames[f], reader->decode_frame(f).value()));
  return {stream.size(), total.psnr_db(info.box_diagonal_mm())};
}

TEST(FastIntraRdo, IntraFramesCostLessAtTheSameQuality) {
  const auto frames = testing::make_moving_analytic_video(64, 2);
  const SequenceInfo info = testing::info_for(frames);
  for (const int qp : {0, 12}) {
    SCOPED_TRACE("qp " + std::to_string(qp));
    EncoderOptions on;
    on.qp = qp;
    on.preset = Preset::kFast;
    on.intra_only = true;
    EncoderOptions off = on;
    off.intra_rdo = false;
    const Rate a = rate(encode_gvid(frames, info, on).value(), frames, info);
    const Rate b = rate(encode_gvid(frames, info, off).value(), frames, info);
    EXPECT_LT(a.bytes, b.bytes);
    EXPECT_GT(a.psnr_db, b.psnr_db - 0.1);
  }
}

TEST(FastIntraRdo, SlowLosslessAndNearLosslessStreamsDoNotChange) {
  const auto frames = testing::make_moving_analytic_video(32, 3);
  const SequenceInfo info = testing::info_for(frames);
  EncoderOptions slow;
  slow.preset = Preset::kSlow;
  slow.qp = 6;
  EncoderOptions lossless;
  lossless.preset = Preset::kFast;
  lossless.lossless = true;
  EncoderOptions near = lossless;
  near.lossless = false;
  near.max_error_mm = 0.05;
  for (const EncoderOptions& on : {slow, lossless, near}) {
    EncoderOptions off = on;
    off.intra_rdo = false;
    EXPECT_EQ(encode_gvid(frames, info, on).value(), encode_gvid(frames, info, off).value());
  }
}

}  // namespace
}  // namespace gvkit::codec
